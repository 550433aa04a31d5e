// The debugging tools on real Mesa drivers (llvmpipe, softpipe and zink through EGL):
// explain with GL backends, driver-vs-driver runs (llvmpipe as the expected side,
// classified by the reference's uncertainty channels), variant detection on every driver
// (zink's GL_SUBPIXEL_BITS finding), and reduce with a GL side in the predicate,
// including an injected GL fault.
#include "fixtures/loader.h"
#include "tests/debug/debug_test_util.h"

namespace rc::debugtest {
namespace {

constexpr const char* kLlvmpipe = "gl:egl:llvmpipe";
constexpr const char* kSoftpipe = "gl:egl:softpipe";
constexpr const char* kZink = "gl:egl:zink";

TEST(DebugGl, ExplainComparesEachGlBackendAtThePixel) {
  const fs::path dir = scratch("explain_gl");
  const std::string fixture = testData("textured_blend_phong.json");
  const Frame ref = renderRef(fixture, dir / "ref");
  const Frame llvm = renderRef(fixture, dir / "llvm", kLlvmpipe);
  const Frame soft = renderRef(fixture, dir / "soft", kSoftpipe);
  const Result r =
      run("explain " + fixture + " --pixel 32,24 --json --backends " + kLlvmpipe + "," + kSoftpipe);
  ASSERT_EQ(r.code, 0) << r.err;
  const json doc = json::parse(r.out);
  checkExplain(doc, ref, "32,24");
  const std::size_t i = ref.index(32, 24);
  for (const auto& [spec, frame, bits] :
       {std::tuple{kLlvmpipe, &llvm, 8}, std::tuple{kSoftpipe, &soft, 4}}) {
    SCOPED_TRACE(spec);
    const json& b = doc["backends"][spec];
    ASSERT_TRUE(b.is_object()) << doc["backends"].dump();
    EXPECT_EQ(b["subpixel_bits"], bits);
    EXPECT_EQ(b["id"].get<std::uint32_t>(), frame->id[i]);
    EXPECT_EQ(static_cast<float>(b["depth"].get<double>()), frame->depth[i]);
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(static_cast<float>(b["color"][c].get<double>()), frame->color[4 * i + c]);
    EXPECT_EQ(b["class"]["visibility"], "match");
    // The verdict there follows from the error and the pixel's own thresholds (a driver
    // may legally warn at 1/64 unit; it must not fail).
    const json& shading = b["class"]["shading"];
    const double err = shading["abs"].get<double>();
    const char* expected_verdict = err > shading["fail_above"].get<double>()   ? "fail"
                                   : err > shading["warn_above"].get<double>() ? "warn"
                                                                               : "pass";
    EXPECT_EQ(shading["verdict"], expected_verdict) << shading.dump();
    EXPECT_NE(shading["verdict"], "fail") << shading.dump();
    EXPECT_EQ(b["class"]["depth"]["verdict"], "pass");
    // The depth error it reports is the one between the two frames.
    EXPECT_NEAR(b["class"]["depth"]["steps"].get<double>(),
                std::fabs(static_cast<double>(frame->depth[i]) - ref.depth[i]) * 16777215.0, 1e-3);
  }
  const Result text = run("explain " + fixture + " --pixel 32,24 --backends " + kLlvmpipe);
  EXPECT_NE(text.out.find(std::string(kLlvmpipe) + ": primitive"), std::string::npos) << text.out;
  fs::remove_all(dir);
}

TEST(DebugGl, ExplainJsonKeysBothWaysIncludingABackendThatCannotRun) {
  const std::set<std::string> documented = documentedKeys();
  std::set<std::string> seen;
  // gl:egl-device needs a GPU: here it cannot start, so its entry is an error (exit 3).
  const Result failing = run("explain " + catalog("transparency/alpha_quads.json") +
                             " --pixel 70,70 --json --backends gl:egl-device:7," + kLlvmpipe);
  EXPECT_EQ(failing.code, 3) << failing.err;
  const json doc = json::parse(failing.out);
  EXPECT_TRUE(doc["backends"]["gl:egl-device:7"].contains("error"));
  EXPECT_EQ(doc["backends"][kLlvmpipe]["class"]["visibility"], "match");
  collectKeys(doc, "", seen);
  // ref:abuffer among the backends adds the A-buffer's list (documented keys abuffer.*).
  const Result ok = run("explain " + testData("textured_blend_phong.json") +
                        " --pixel 32,24 --json --backends ref:abuffer," + kSoftpipe);
  ASSERT_EQ(ok.code, 0) << ok.err;
  collectKeys(json::parse(ok.out), "", seen);
  // A stencil test (documented keys fragments[].ops.stencil.*).
  const Result stencil = run("explain " + catalog("fragment-ops/stencil_portal.json") +
                             " --pixel 80,60 --json --backends " + kLlvmpipe);
  ASSERT_EQ(stencil.code, 0) << stencil.err;
  collectKeys(json::parse(stencil.out), "", seen);
  // Level-of-detail sampling (documented keys fragments[].shading.texture_lod.*).
  const Result lod = run("explain " + catalog("mipmap/level_colours.json") +
                         " --pixel 80,60 --json --backends ref");
  ASSERT_EQ(lod.code, 0) << lod.err;
  collectKeys(json::parse(lod.out), "", seen);
  // Lines and points (documented keys fragments[].line.*), against llvmpipe.
  const Result line = run("explain " + catalog("lines/star_octants.json") +
                          " --pixel 95,52 --json --backends " + kLlvmpipe);
  ASSERT_EQ(line.code, 0) << line.err;
  collectKeys(json::parse(line.out), "", seen);
  // A shadow lookup, PCF (documented keys fragments[].shading.lights[].shadow.* and
  // backends.SPEC.shadow_texels[].*), against llvmpipe.
  const Result shadow = run("explain " + catalog("shadow/spot_perspective_pcf.json") +
                            " --pixel 80,110 --json --backends " + kLlvmpipe);
  ASSERT_EQ(shadow.code, 0) << shadow.err;
  const json shadow_doc = json::parse(shadow.out);
  EXPECT_FALSE(shadow_doc["backends"][kLlvmpipe]["shadow_texels"].empty()) << shadow.out;
  // The driver's own map (its pass frame, which the worker sends for explain) at each texel.
  for (const json& t : shadow_doc["backends"][kLlvmpipe]["shadow_texels"])
    EXPECT_TRUE(t["driver"].is_number()) << t.dump();
  collectKeys(shadow_doc, "", seen);
  for (const std::string& k : seen) EXPECT_TRUE(documented.count(k)) << "undocumented key " << k;
  for (const std::string& k : documented) EXPECT_TRUE(seen.count(k)) << "never seen " << k;
}

// One driver-vs-driver run (it renders and probes both drivers, ~20 s), checked three ways
// in one test so that ctest does not repeat it per check.
void checkClassification(const json& report, const fs::path& dir, int exit_code,
                         const std::string& log);
void checkVariants(const json& report);
void checkHtml(const fs::path& dir);

TEST(DebugGl, DriverVsDriverRunClassifiesProbesAndReports) {
  const fs::path dir = scratch("d2d");
  const std::string fixtures = catalog("coverage/triangle_fan.json") + " " +
                               catalog("coverage/slivers_and_centres.json") + " " +
                               catalog("shading/sphere_gouraud_low.json") + " " +
                               catalog("zbuffer/cyclic_overlap_zbuffer.json");
  // --keep-frames: the frames of passing pairs too, to read their frame.json below.
  const Result r =
      run("run " + fixtures + " --backends " + kLlvmpipe + "," + kSoftpipe +
          ",ref:painter --against " + kLlvmpipe + " --keep-frames --out " + dir.string());
  const json report = json::parse(std::ifstream(dir / "report.json"));
  {
    SCOPED_TRACE("classification");
    checkClassification(report, dir, r.code, r.out + r.err);
  }
  {
    SCOPED_TRACE("variants");
    checkVariants(report);
  }
  {
    SCOPED_TRACE("report.html");
    checkHtml(dir);
  }
  fs::remove_all(dir);
}

void checkClassification(const json& report, const fs::path& dir, int exit_code,
                         const std::string& log) {
  // ref:painter against llvmpipe fails on the cyclic overlap: the run can fail.
  EXPECT_EQ(exit_code, 1) << log;
  int softpipe_pairs = 0;
  std::uint64_t ambiguous = 0;
  for (const json& r : report["results"]) {
    EXPECT_EQ(r["expected"], kLlvmpipe);
    if (r["actual"] == "ref:painter") {
      if (r["fixture"] == "zbuffer/cyclic_overlap_zbuffer") {
        EXPECT_EQ(r["status"], "fail");
        EXPECT_GT(r["visibility"]["wrong_primitive_hard"].get<int>(), 0);
      }
      continue;
    }
    ASSERT_EQ(r["actual"], kSoftpipe);
    ++softpipe_pairs;
    SCOPED_TRACE(r["fixture"].get<std::string>());
    EXPECT_NE(r["status"], "error") << r.dump();
    EXPECT_TRUE(r["visibility"]["uncertainty_available"].get<bool>());
    EXPECT_EQ(r["subpixel_bits"]["expected"], 8);
    EXPECT_EQ(r["subpixel_bits"]["actual"], 4);
    EXPECT_EQ(r["visibility"]["hard"], 0) << r["visibility"].dump();
    ambiguous += r["visibility"]["ambiguous"].get<std::uint64_t>();
    // Visibility band (docs/tolerances.md): edge_dist is measured to the exact edges, so
    // the larger of the two sides' snap moves, plus 16 float ulps of the window transform.
    const double snap4 = std::sqrt(2.0) / 2.0 / 16.0;
    const int side = std::max(r["width"].get<int>(), r["height"].get<int>());
    EXPECT_NEAR(r["visibility"]["band_px"].get<double>(),
                snap4 + 16.0 * std::ldexp(1.0, -24) * side, 1e-12);
  }
  EXPECT_EQ(softpipe_pairs, 4);
  // The drivers really disagree at edges (softpipe's tie-break differs): all excused.
  EXPECT_GT(ambiguous, 0u);
  // Each frame.json records the queried subpixel bits.
  for (const auto& [spec, bits] : {std::pair{kLlvmpipe, 8}, std::pair{kSoftpipe, 4}}) {
    const fs::path frame = dir / "frames" / "coverage__triangle_fan" /
                           (std::string(spec) == kLlvmpipe ? "gl_egl_llvmpipe" : "gl_egl_softpipe");
    ASSERT_TRUE(fs::exists(frame / "frame.json")) << frame;
    EXPECT_EQ(readFrameDir(frame).meta["subpixel_bits"], bits);
  }
}

// Variant detection finds 8 bits for llvmpipe and 4 (queried) for softpipe.
void checkVariants(const json& report) {
  const json& v = report["variants"];
  ASSERT_TRUE(v.contains(kLlvmpipe) && v.contains(kSoftpipe)) << v.dump(1);
  EXPECT_FALSE(v.contains("ref:painter"));  // only GL backends are probed

  const json& llvm = v[kLlvmpipe];
  EXPECT_EQ(llvm["subpixel_bits"], 8);
  EXPECT_EQ(llvm["subpixel"]["queried"], 8);
  EXPECT_EQ(llvm["subpixel"]["best"], 8);
  EXPECT_TRUE(llvm["subpixel"]["confirmed"].get<bool>());
  EXPECT_EQ(llvm["subpixel"]["mismatches"]["8"], 0);
  EXPECT_GT(llvm["subpixel"]["mismatches"]["7"].get<int>(), 0);
  EXPECT_GT(llvm["subpixel"]["mismatches"]["9"].get<int>(), 0);
  EXPECT_EQ(llvm["tie_break"]["rule"], "left+bottom");
  EXPECT_EQ(llvm["tie_break"]["shared_edges"]["gaps"], 0);
  EXPECT_TRUE(llvm["tie_break"]["matches_reference"].get<bool>());
  EXPECT_EQ(llvm["depth_rounding"]["rule"], "nearest");
  EXPECT_TRUE(llvm["depth_rounding"]["matches_reference"].get<bool>());

  // softpipe reports GL_SUBPIXEL_BITS = 4, but (Mesa 22.3.6, sp_setup.c) it walks its
  // edges in float without snapping: no precision up to 12 bits is coarser than it, and
  // 4 bits is clearly not what it does. Its tie-break and depth conversion differ too.
  const json& soft = v[kSoftpipe];
  EXPECT_EQ(soft["subpixel_bits"], 4);
  EXPECT_EQ(soft["subpixel"]["queried"], 4);
  EXPECT_FALSE(soft["subpixel"]["confirmed"].get<bool>());
  EXPECT_GT(soft["subpixel"]["mismatches"]["4"].get<int>(), 100);
  EXPECT_GE(soft["subpixel"]["best"].get<int>(), 11);
  EXPECT_EQ(soft["tie_break"]["rule"], "right+bottom");
  EXPECT_EQ(soft["tie_break"]["shared_edges"]["gaps"], 0);
  EXPECT_FALSE(soft["tie_break"]["matches_reference"].get<bool>());
  EXPECT_EQ(soft["depth_rounding"]["rule"], "truncate");
  EXPECT_FALSE(soft["depth_rounding"]["matches_reference"].get<bool>());
}

void checkHtml(const fs::path& dir) {
  std::ifstream in(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("Fixture &times; backend"), std::string::npos);
  EXPECT_NE(html.find("every backend compared against gl:egl:llvmpipe"), std::string::npos);
  EXPECT_NE(html.find("<th>gl:egl:softpipe</th>"), std::string::npos);
  EXPECT_NE(html.find("<th>ref:painter</th>"), std::string::npos);
  EXPECT_NE(html.find("Backend variants"), std::string::npos);
  EXPECT_NE(html.find("NOT confirmed"), std::string::npos);
  EXPECT_NE(html.find("left+bottom"), std::string::npos);
}

// zink against llvmpipe: lavapipe under zink is llvmpipe's rasterizer, so the frames agree
// up to the snap band, and the probe finds what zink's GL_SUBPIXEL_BITS hides.
TEST(DebugGl, ZinkAgainstLlvmpipeAndItsSubpixelFinding) {
  const fs::path dir = scratch("zink");
  const std::string fixtures =
      catalog("coverage/triangle_fan.json") + " " + catalog("coverage/slivers_and_centres.json");
  const Result r = run("run " + fixtures + " --backends " + kZink + " --against " + kLlvmpipe +
                       " --out " + dir.string());
  ASSERT_EQ(r.code, 0) << r.out + r.err;
  const json report = json::parse(std::ifstream(dir / "report.json"));
  ASSERT_EQ(report["results"].size(), 2u);
  for (const json& row : report["results"]) {
    SCOPED_TRACE(row["fixture"].get<std::string>());
    EXPECT_EQ(row["actual"], kZink);
    EXPECT_EQ(row["status"], "pass") << row.dump();
    // The band comes from the bits each frame carries: 8 on both sides, not zink's
    // GL_SUBPIXEL_BITS 4 (which would widen it fifteen-fold).
    EXPECT_EQ(row["subpixel_bits"]["actual"], 8);
    const double snap8 = std::sqrt(2.0) / 2.0 / 256.0;
    const int side = std::max(row["width"].get<int>(), row["height"].get<int>());
    EXPECT_NEAR(row["visibility"]["band_px"].get<double>(),
                snap8 + 16.0 * std::ldexp(1.0, -24) * side, 1e-12);
    const json& stack = row["stacks"]["actual"];
    EXPECT_EQ(stack["gl_subpixel_bits"], 4);
    EXPECT_EQ(stack["vulkan"]["subpixel_precision_bits"], 8);
    EXPECT_FALSE(row["stacks"]["expected"].contains("vulkan"));  // llvmpipe: no Vulkan
  }
  const json& z = report["variants"][kZink];
  EXPECT_EQ(z["subpixel_bits"], 4);
  EXPECT_EQ(z["band_subpixel_bits"], 8);
  EXPECT_EQ(z["subpixel"]["queried"], 4);
  EXPECT_EQ(z["subpixel"]["best"], 8);
  EXPECT_FALSE(z["subpixel"]["confirmed"].get<bool>());
  EXPECT_TRUE(z["subpixel"]["band_confirmed"].get<bool>());
  EXPECT_GT(z["subpixel"]["mismatches"]["4"].get<int>(), 100);
  EXPECT_EQ(z["tie_break"]["rule"], "left+bottom");
  EXPECT_EQ(z["depth_rounding"]["rule"], "nearest");
  const std::string finding =
      "subpixel: GL_SUBPIXEL_BITS says 4 but the driver rasterizes like 8 bits";
  EXPECT_EQ(z["findings"], json::array({finding}));
  EXPECT_TRUE(report["variants"][kLlvmpipe]["findings"].empty());
  EXPECT_NE(r.out.find(std::string("finding: ") + kZink + ": " + finding), std::string::npos)
      << r.out;
  std::ifstream in(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find(finding), std::string::npos);
  if (std::system("/usr/bin/python3 -c 'import jsonschema' 2>/dev/null") == 0) {
    const Result valid = rc::test::runShell(
        "/usr/bin/python3 -c \"import json,sys,jsonschema; jsonschema.validate(json.load(open("
        "sys.argv[1])), json.load(open(sys.argv[2])))\" '" +
        (dir / "report.json").string() + "' '" RC_SOURCE_DIR "/docs/report-schema.json'");
    EXPECT_EQ(valid.code, 0) << valid.out << valid.err;
  }
  fs::remove_all(dir);
}

TEST(DebugGl, SingleDriverVsDriverPairStillGetsTheMatrix) {
  const fs::path dir = scratch("d2d_one");
  const Result r =
      run("run " + catalog("coverage/triangle_fan.json") + " --backends " + kLlvmpipe + "," +
          kSoftpipe + " --against " + kLlvmpipe + " --no-variants --out " + dir.string());
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  std::ifstream in(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("Fixture &times; backend"), std::string::npos);
  EXPECT_EQ(html.find("Backend variants"), std::string::npos);  // --no-variants
  const json report = json::parse(std::ifstream(dir / "report.json"));
  EXPECT_FALSE(report.contains("variants"));
  fs::remove_all(dir);
}

TEST(DebugGl, ReduceWithAGlSideInThePredicate) {
  const fs::path dir = scratch("reduce_gl");
  const fs::path out = dir / "min.json";
  const Result r = run("reduce " + catalog("zbuffer/cyclic_overlap_zbuffer.json") + " --expected " +
                       kLlvmpipe + " --actual ref:painter --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const Scene min = loadScene(out);
  std::size_t triangles = 0;
  for (const Object& o : min.objects) triangles += o.mesh.triangles.size();
  EXPECT_LE(triangles, 3u);
  const Result again = run("run " + out.string() + " --backends ref:painter --against " +
                           kLlvmpipe + " --no-variants --out " + (dir / "run").string());
  EXPECT_EQ(again.code, 1) << again.out;
  fs::remove_all(dir);
}

// RASTERCHECK_GL_FAULT (test-only, in the GL backend): drop_primitive=ID makes GL skip the
// triangle with that primitive id.
constexpr const char* kFault = "RASTERCHECK_GL_FAULT=drop_primitive=3";

// The fault hook must be there and work: the injected frame says so in frame.json and
// has lost primitive 3 (a build without the hook fails here instead of skipping).
void expectFaultInjected(const fs::path& dir) {
  const Frame f = renderRef(catalog("coverage/triangle_fan.json"), dir / "probe", kLlvmpipe);
  const Result r = run("render " + catalog("coverage/triangle_fan.json") + " --backend " +
                           kLlvmpipe + " --out " + (dir / "faulty").string(),
                       kFault);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const Frame g = readFrameDir(dir / "faulty");
  ASSERT_TRUE(g.meta.contains("fault_injected"))
      << "the GL backend ignored " << kFault << " (no fault_injected in frame.json)";
  EXPECT_EQ(g.meta["fault_injected"], "drop_primitive=3");
  ASSERT_GT(std::count(f.id.begin(), f.id.end(), 3u), 0) << "the fixture has no primitive 3";
  ASSERT_EQ(std::count(g.id.begin(), g.id.end(), 3u), 0) << "primitive 3 was not dropped";
}

TEST(DebugGl, ReduceAnInjectedGlFault) {
  const fs::path dir = scratch("reduce_fault");
  ASSERT_NO_FATAL_FAILURE(expectFaultInjected(dir));
  const std::string fixture = catalog("coverage/triangle_fan.json");
  const fs::path out = dir / "min.json";
  const Result r =
      run("reduce " + fixture + " --expected ref --actual " + kLlvmpipe + " --out " + out.string(),
          kFault);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const Scene min = loadScene(out);
  std::size_t triangles = 0;
  for (const Object& o : min.objects) triangles += o.mesh.triangles.size();
  // Primitive 3 must exist, so at least 3 triangles; a handful at most.
  EXPECT_GE(triangles, 3u);
  EXPECT_LE(triangles, 5u);
  // It fails with the fault and passes without it: the reduction kept the bug, not noise.
  const std::string again =
      "run " + out.string() + " --backends " + kLlvmpipe + " --against ref --no-variants --out ";
  EXPECT_EQ(run(again + (dir / "with").string(), kFault).code, 1);
  EXPECT_EQ(run(again + (dir / "without").string()).code, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rc::debugtest
