// The GL backend's contract around the pixels: spec parsing, driver identity and
// frame.json metadata, every failure path as BackendError/InputError (with injected
// faults: a broken shader, a GL error, a driver substitution, a second driver in one
// process), and bad input that must not crash.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fixtures/loader.h"
#include "fixtures/scene_logic.h"
#include "gl_backend/gl_testing.h"
#include "tests/gl/gl_test_util.h"
#include "tests/support/random_fixtures.h"

namespace rc::gltest {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(GlSpecParse, AcceptsEveryDocumentedForm) {
  struct Case {
    const char* text;
    GlSpec::Platform platform;
    const char* driver;
    int device;
    const char* canonical;
  };
  const Case cases[] = {
      {"gl", GlSpec::Platform::EglSurfaceless, "", -1, "gl"},
      {"gl:egl", GlSpec::Platform::EglSurfaceless, "", -1, "gl"},
      {"gl:egl:llvmpipe", GlSpec::Platform::EglSurfaceless, "llvmpipe", -1, "gl:egl:llvmpipe"},
      {"gl:egl:softpipe", GlSpec::Platform::EglSurfaceless, "softpipe", -1, "gl:egl:softpipe"},
      {"gl:egl:zink", GlSpec::Platform::EglSurfaceless, "zink", -1, "gl:egl:zink"},
      {"gl:osmesa", GlSpec::Platform::OSMesa, "", -1, "gl:osmesa"},
      {"gl:osmesa:llvmpipe", GlSpec::Platform::OSMesa, "llvmpipe", -1, "gl:osmesa:llvmpipe"},
      {"gl:osmesa:softpipe", GlSpec::Platform::OSMesa, "softpipe", -1, "gl:osmesa:softpipe"},
      {"gl:egl-device", GlSpec::Platform::EglDevice, "", -1, "gl:egl-device"},
      {"gl:egl-device:0", GlSpec::Platform::EglDevice, "", 0, "gl:egl-device:0"},
      {"gl:egl-device:12", GlSpec::Platform::EglDevice, "", 12, "gl:egl-device:12"},
  };
  for (const Case& c : cases) {
    const GlSpec s = parseGlSpec(c.text);
    EXPECT_EQ(s.platform, c.platform) << c.text;
    EXPECT_EQ(s.driver, c.driver) << c.text;
    EXPECT_EQ(s.device, c.device) << c.text;
    EXPECT_EQ(toString(s), c.canonical) << c.text;
    const GlSpec again = parseGlSpec(toString(s));
    EXPECT_EQ(again.platform, s.platform);
    EXPECT_EQ(again.driver, s.driver);
    EXPECT_EQ(again.device, s.device);
  }
}

TEST(GlSpecParse, RejectsEverythingElseWithTheValidForms) {
  for (const char* bad : {"",
                          "g",
                          "GL",
                          "gl:",
                          "gl:egl:",
                          "gl:osmesa:zink",
                          "gl:egl:llvmpipe:x",
                          "gl:osmesa:swrast",
                          "gl:egl-device:",
                          "gl:egl-device:-1",
                          "gl:egl-device:1x",
                          "gl:egl-device:llvmpipe",
                          "gl:vulkan",
                          "ref",
                          "gl:eglx",
                          " gl",
                          "gl:egl:llvmpipe@",
                          "@/usr/lib",
                          "gl:egl:foo@/tmp",
                          "ref@/tmp"}) {
    try {
      parseGlSpec(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_THAT(std::string(e.what()), HasSubstr(std::string("'") + bad + "'"));
      EXPECT_THAT(std::string(e.what()), HasSubstr("gl:osmesa:softpipe"));
      EXPECT_THAT(std::string(e.what()), HasSubstr("gl:egl-device:N"));
    }
  }
}

TEST(GlSpecParse, MesaFolderSuffixOnEveryForm) {
  // Grammar only: everything after the first '@' is the folder, ':' and '@' included.
  for (const char* base : {"gl", "gl:egl", "gl:egl:llvmpipe", "gl:egl:zink", "gl:osmesa:softpipe",
                           "gl:egl-device:1"}) {
    const std::string text = std::string(base) + "@/opt/mesa:x@y/lib";
    const GlSpec s = parseGlSpecSyntax(text);
    const GlSpec plain = parseGlSpecSyntax(base);
    EXPECT_EQ(s.mesa_dir, "/opt/mesa:x@y/lib") << text;
    EXPECT_EQ(s.platform, plain.platform) << text;
    EXPECT_EQ(s.driver, plain.driver) << text;
    EXPECT_EQ(s.device, plain.device) << text;
    EXPECT_EQ(toString(s), toString(plain) + "@/opt/mesa:x@y/lib") << text;
    EXPECT_EQ(parseGlSpecSyntax(toString(s)).mesa_dir, s.mesa_dir);
  }
  EXPECT_TRUE(parseGlSpecSyntax("gl:egl:llvmpipe").mesa_dir.empty());
}

// A folder with empty files of the given names (checkMesaDir looks only at names).
fs::path fakeMesaDir(const std::string& name, std::initializer_list<const char*> files) {
  fs::path dir =
      fs::temp_directory_path() / ("rc_fake_mesa_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* f : files) std::ofstream(dir / f) << "";
  return dir;
}

TEST(GlSpecParse, MesaFolderMustHoldWhatThePlatformLoads) {
  const fs::path egl = fakeMesaDir("egl", {"libEGL_mesa.so.0"});
  const fs::path full = fakeMesaDir("full", {"libEGL.so.1", "libvulkan_lvp.so", "libOSMesa.so.8"});
  const fs::path empty = fakeMesaDir("empty", {});
  EXPECT_EQ(parseGlSpec("gl:egl:llvmpipe@" + egl.string()).mesa_dir, egl.string());
  EXPECT_NO_THROW(parseGlSpec("gl:egl:zink@" + full.string()));
  EXPECT_NO_THROW(parseGlSpec("gl@" + full.string()));
  auto error = [](const std::string& spec) {
    try {
      parseGlSpec(spec);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string missing = error("gl:egl:llvmpipe@/nonexistent/mesa");
  EXPECT_THAT(missing, HasSubstr("backend 'gl:egl:llvmpipe@/nonexistent/mesa': Mesa folder "
                                 "/nonexistent/mesa does not exist"));
  EXPECT_THAT(error("gl:egl@" + (egl / "libEGL_mesa.so.0").string()), HasSubstr("is not a folder"));
  EXPECT_THAT(error("gl:egl:softpipe@" + empty.string()),
              HasSubstr("holds neither libEGL_mesa.so.0 nor libEGL.so.1"));
  EXPECT_THAT(error("gl:egl:zink@" + egl.string()), HasSubstr("holds no libvulkan_lvp.so"));
  EXPECT_THAT(error("gl:osmesa:llvmpipe@" + egl.string()), HasSubstr("holds no libOSMesa"));
  for (const std::string& msg : {missing, error("gl:egl:zink@" + egl.string())})
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  for (const fs::path& d : {egl, full, empty}) fs::remove_all(d);
}

TEST(GlSpecParse, StartupEnvironmentPutsTheMesaFolderFirstOnce) {
  const fs::path dir = fakeMesaDir("startup", {"libEGL_mesa.so.0"});
  const GlSpec s = parseGlSpec("gl:egl:llvmpipe@" + dir.string());
  EXPECT_TRUE(startupEnvironment(parseGlSpec("gl:egl:llvmpipe")).empty());
  // The environment is passed in, not set: this process may run a GL driver's threads
  // (the zink pass of these tests), and setenv beside their getenv is a data race (it
  // crashed and hung gl_egl_zink.all here).
  const auto env = startupEnvironment(s, "/elsewhere");
  ASSERT_EQ(env.size(), 1u);
  EXPECT_EQ(env[0].first, "LD_LIBRARY_PATH");
  EXPECT_EQ(env[0].second, fs::canonical(dir).string() + ":/elsewhere");
  // Once in place it is returned unchanged: `render` restarts itself at most once.
  EXPECT_EQ(startupEnvironment(s, env[0].second.c_str()), env);
  EXPECT_EQ(startupEnvironment(s, nullptr)[0].second, fs::canonical(dir).string());
  fs::remove_all(dir);
}

TEST(GlEglDevice, NoGpuIsABackendErrorSayingSo) {
  // This machine has no GPU (Mesa may list only its software device). Where a GPU
  // exists the render must succeed and report a non-software renderer instead.
  Scene s = orthoScene(4, 4);
  s.name = "gltest/device";
  try {
    const Frame f = renderGl(s, parseGlSpec("gl:egl-device"));
    const std::string driver = f.meta.at("driver");
    EXPECT_NE(driver, "llvmpipe");
    EXPECT_NE(driver, "softpipe");
    EXPECT_EQ(f.meta.at("platform"), "egl-device");
  } catch (const BackendError& e) {
    const std::string msg = e.what();
    EXPECT_THAT(msg, HasSubstr("gltest/device: gl:egl-device: "));
    EXPECT_THAT(msg, HasSubstr("no EGL device with a GPU"));
  }
  // An index past the device list is never a software fallback.
  EXPECT_THROW(renderGl(s, parseGlSpec("gl:egl-device:99")), BackendError);
}

class GlBackend : public GlTest {};

TEST_F(GlBackend, DriverAndMetadataMatchTheSpec) {
  const GlSpec sp = spec();
  const Frame f = render(orthoScene(4, 4));
  const std::string renderer = f.meta.at("gl_renderer");
  EXPECT_EQ(f.meta.at("renderer"), renderer);
  if (!sp.driver.empty()) {
    EXPECT_THAT(renderer, HasSubstr(sp.driver));
    EXPECT_EQ(f.meta.at("driver"), sp.driver);
  }
  // Measured on Mesa 22.3: llvmpipe snaps to 1/256 px, softpipe to 1/16 px; zink answers
  // GL_SUBPIXEL_BITS 4 but lavapipe under it snaps to 1/256 px, what its Vulkan device
  // says and what the frame carries for the comparator.
  const std::string driver = f.meta.at("driver");
  if (driver == "llvmpipe") {
    EXPECT_EQ(f.meta.at("subpixel_bits"), 8);
    EXPECT_EQ(f.meta.at("gl_subpixel_bits"), 8);
  }
  if (driver == "softpipe") {
    EXPECT_EQ(f.meta.at("subpixel_bits"), 4);
    EXPECT_EQ(f.meta.at("subpixel_bits_source"), "GL_SUBPIXEL_BITS");
  }
  if (driver == "zink") {
    EXPECT_EQ(f.meta.at("gl_subpixel_bits"), 4);
    EXPECT_EQ(f.meta.at("subpixel_bits"), 8);
    EXPECT_EQ(f.meta.at("subpixel_bits_source"), "VkPhysicalDeviceLimits::subPixelPrecisionBits");
    // The Vulkan device is the one zink names in GL_RENDERER: "zink (<device>)".
    const nlohmann::json& vk = f.meta.at("vulkan");
    EXPECT_EQ("zink (" + vk.at("device").get<std::string>() + ")", renderer);
    EXPECT_EQ(vk.at("device_type"), "cpu");
    EXPECT_EQ(vk.at("subpixel_precision_bits"), 8);
    EXPECT_THAT(vk.at("driver_info").get<std::string>(), HasSubstr("Mesa"));
    EXPECT_THAT(std::string(f.meta.at("stack")), HasSubstr("| Vulkan "));
  } else {
    EXPECT_FALSE(f.meta.contains("vulkan"));
  }
  // Which Mesa: its version from GL_VERSION, and the driver library really mapped.
  const nlohmann::json& mesa = f.meta.at("mesa");
  EXPECT_THAT(std::string(f.meta.at("gl_version")),
              HasSubstr(mesa.at("version").get<std::string>()));
  EXPECT_TRUE(mesa.at("dir").is_null());
  const std::vector<std::string> libs = mesa.at("libraries");
  const std::string driver_library = mesa.at("driver_library");
  EXPECT_NE(std::find(libs.begin(), libs.end(), driver_library), libs.end());
  EXPECT_TRUE(fs::exists(driver_library)) << driver_library;
  EXPECT_THAT(std::string(f.meta.at("stack")), HasSubstr(renderer));
  EXPECT_EQ(f.meta.at("platform"), sp.platform == GlSpec::Platform::OSMesa ? "osmesa" : "egl");
  EXPECT_THAT(std::string(f.meta.at("gl_version")), HasSubstr("Mesa"));
  EXPECT_FALSE(std::string(f.meta.at("glsl_version")).empty());
  for (const char* key : {"context", "upload", "draw", "readback"})
    EXPECT_GE(f.meta.at("timing_ms").at(key).get<double>(), 0.0) << key;
  EXPECT_TRUE(f.edge_dist.empty());
  EXPECT_TRUE(f.depth_gap.empty());
}

TEST_F(GlBackend, RowZeroIsTheTopRow) {
  // A quad covering only the top half of the view: image rows 0..3 covered, 4..7 not.
  Scene s = orthoScene(8, 8);
  s.ambient_light = glm::dvec3(1.0);
  Material m;
  m.ambient = {1, 1, 1};
  s.materials.push_back(m);
  s.objects.push_back(quad(-2, 0.0, 2, 2, 0, 0));
  const Frame f = render(s);
  for (int y = 0; y < 8; ++y) EXPECT_EQ(f.id[f.index(3, y)] != 0, y < 4) << "row " << y;
}

TEST_F(GlBackend, RepeatedRendersAreIdentical) {
  Scene s = orthoScene(24, 16);
  s.ambient_light = {0.1, 0.2, 0.3};
  Material m;
  m.ambient = {1, 1, 1};
  m.specular = {0.5, 0.5, 0.5};
  s.materials.push_back(m);
  Light l;
  l.position = {0.3, 0.2, 1.0};
  s.lights.push_back(l);
  Object o = quad(-0.9, -0.8, 0.7, 0.9, 0.1, 0);
  o.mesh.positions[2].z = -0.4f;
  s.objects.push_back(o);
  const Frame a = render(s);
  const Frame b = render(s);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.id, b.id);
}

// Restores the hooks whatever the test does.
struct HookGuard {
  HookGuard() = default;
  HookGuard(const HookGuard&) = delete;
  HookGuard& operator=(const HookGuard&) = delete;
  ~HookGuard() { gl::testing::hooks() = gl::testing::Hooks{}; }
};

// Both readback paths (rows inverted by GL_MESA_pack_invert, or swapped afterwards) give
// the same frame for every colour and depth format, at an odd height (middle row).
// llvmpipe, zink and softpipe reuse the process's context and its programs from one render to
// the next, whatever they draw (a driver the isolation test has not run on gets a new context
// per render); a render that failed halfway is followed by a new context ("replaced"), and the
// next reuses that one.
TEST_F(GlBackend, ContextIsReusedWhereIsolationIsShown) {
  Scene s = orthoScene(8, 8);
  s.objects.push_back(quad(-1, -1, 1, 1, 0, addMaterial(s, Material{})));
  render(s);
  const Frame a = render(s);
  const std::string driver = a.meta.at("driver");
  const char* forced = std::getenv("RASTERCHECK_GL_CONTEXT");
  const bool keeps = forced != nullptr
                         ? std::string(forced) == "reuse"
                         : driver == "llvmpipe" || driver == "zink" || driver == "softpipe";
  EXPECT_EQ(a.meta.at("context"), keeps ? "reused" : "new");
  EXPECT_EQ(a.meta.at("program"), keeps ? "reused" : "compiled");
  {
    HookGuard guard;
    gl::testing::hooks().gl_error_after_upload = true;
    EXPECT_THROW(render(s), BackendError);
  }
  const Frame b = render(s);
  EXPECT_EQ(b.meta.at("context"), keeps ? "replaced" : "new");
  EXPECT_EQ(b.meta.at("program"), "compiled");
  const Frame c = render(s);
  EXPECT_EQ(c.meta.at("context"), keeps ? "reused" : "new");
  EXPECT_EQ(c.color, a.color);
  EXPECT_EQ(c.id, a.id);
  if (forced != nullptr) return;
  // Blending onto rgba8 and lines too (softpipe took new contexts for them before
  // FallbackFlush).
  Scene blended = s;
  blended.materials[0].opacity = 0.5;
  blended.state.blend = Blend::Alpha;
  blended.state.color_format = ColorFormat::RGBA8;
  EXPECT_EQ(render(blended).meta.at("context"), keeps ? "reused" : "new");
  Scene wire = s;
  wire.objects[0].state.polygon_mode = PolygonMode::Line;
  EXPECT_EQ(render(wire).meta.at("context"), keeps ? "reused" : "new");
}

// One quad wound clockwise (back-facing) with culling off: the last triangle a driver sets up
// in it faces away.
Scene backFacingQuad() {
  Scene s = orthoScene(8, 8);
  Object o = quad(-1, -1, 1, 1, 0, addMaterial(s, Material{}));
  o.mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
  s.objects.push_back(o);
  return s;
}

bool drawsLinesOrPoints(const Scene& scene) {
  const std::vector<DrawPass> passes = drawPasses(scene);
  return std::any_of(passes.begin(), passes.end(),
                     [](const DrawPass& p) { return p.rasterizesLinesOrPoints(); });
}

// `scene` rendered in a reused context right after `before` must give the bits of a new
// context on every driver that reuses its context; on softpipe, with the emulation that
// `off` names turned off, the reused context's frame must differ (the emulation is what it
// takes). Skipped where RASTERCHECK_GL_CONTEXT decides contexts or the driver takes a new
// one per render.
void expectReusedLikeNew(const Scene& scene, const Scene& before, bool gl::testing::Hooks::*off) {
  const char* outer = std::getenv("RASTERCHECK_GL_CONTEXT");
  if (outer != nullptr) GTEST_SKIP() << "RASTERCHECK_GL_CONTEXT=" << outer << " decides contexts";
  ::setenv("RASTERCHECK_GL_CONTEXT", "new", 1);
  const Frame fresh = GlTest::render(scene);
  ::unsetenv("RASTERCHECK_GL_CONTEXT");
  const std::string driver = fresh.meta.at("driver");
  if (driver != "llvmpipe" && driver != "zink" && driver != "softpipe")
    GTEST_SKIP() << driver << " gets a new context per render";
  GlTest::render(before);
  const Frame reused = GlTest::render(scene);
  EXPECT_EQ(reused.meta.at("context"), "reused");
  EXPECT_TRUE(test::framePlanes(reused) == test::framePlanes(fresh));
  if (driver != "softpipe") return;
  HookGuard guard;
  gl::testing::hooks().*off = true;
  GlTest::render(before);
  const Frame without = GlTest::render(scene);
  EXPECT_EQ(without.meta.at("context"), "reused");
  EXPECT_FALSE(test::framePlanes(without) == test::framePlanes(fresh));
}

// Mesa creates its fallback texture (what a sampler reads where its unit has no texture) the
// first time a context draws with such a unit, and flushes the context when it does; softpipe
// blends after that flush over the stored 8-bit colour instead of its tile cache's floats. In
// transparency/softpipe_unclamped_clear_blend the textured quad comes first, so a new context
// flushes between the two quads; a context reused after a render of an untextured material
// has the fallback already, and FallbackFlush flushes there in its place. Every driver must
// give the new context's bits in the reused one; on softpipe, without the harness's flush
// (the no_fallback_flush hook) the frame differs, which shows the flush is what it takes.
TEST_F(GlBackend, AReusedContextFlushesWhereANewOneCreatesItsFallbackTexture) {
  Scene untextured = orthoScene(8, 8);
  untextured.objects.push_back(quad(-1, -1, 1, 1, 0, addMaterial(untextured, Material{})));
  expectReusedLikeNew(loadScene(fs::path(RC_SOURCE_DIR) / "fixtures" / "scenes" / "transparency" /
                                "softpipe_unclamped_clear_blend.json"),
                      untextured, &gl::testing::Hooks::no_fallback_flush);
}

// softpipe gives lines and points the facing of the last triangle it set up (their two-sided
// stencil state and gl_FrontFacing); a new context starts at front. In
// lines/polygon_mode_back_stencil back faces never pass the stencil test: drawn after a
// back-facing triangle in a reused context its lines vanished. resetSetupFacing sets the
// facing back before each render in a reused softpipe context; without it (the
// no_facing_reset hook) the frame differs from the new context's.
TEST_F(GlBackend, AReusedContextDrawsLinesWithTheFacingOfANewOne) {
  expectReusedLikeNew(loadScene(fs::path(RC_SOURCE_DIR) / "fixtures" / "scenes" / "lines" /
                                "polygon_mode_back_stencil.json"),
                      backFacingQuad(), &gl::testing::Hooks::no_facing_reset);
}

// `count` small random fixtures of every profile (written to `dir`) and the whole catalog,
// sorted: the scenes the tests below draw twice and compare bit for bit.
std::vector<fs::path> randomAndCatalog(const fs::path& dir, std::uint64_t seed, int count) {
  return test::randomAndCatalog(dir, seed, count, fs::path(RC_SOURCE_DIR) / "fixtures" / "scenes");
}

// Isolation: a fixture's frame does not depend on what this process drew before it. Random
// scenes (every profile, small) and the whole catalog (textures, blending, MSAA, every
// format) are rendered each in a new context (RASTERCHECK_GL_CONTEXT=new), then in a
// shuffled order with the context this driver keeps (or the one RASTERCHECK_GL_CONTEXT
// names), and every plane of every frame must be the new context's bits. This is what lets a
// driver reuse its context (ContextIsReusedWhereIsolationIsShown). Tried: with the front face
// set only for clockwise scenes it fails on llvmpipe at the first counter-clockwise scene
// drawn after a clockwise one; without FallbackFlush, in a reused softpipe context it fails at
// transparency/softpipe_unclamped_clear_blend, blended rgba8 and line scenes (7 of them).
// Then every scene with lines or points again, right after a back-facing triangle.
TEST_F(GlBackend, FramesDoNotDependOnWhatWasDrawnBefore) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("rc_isolation_" + std::to_string(getpid()));
  const std::vector<fs::path> files = randomAndCatalog(dir, 20261204, 8);
  ASSERT_GE(files.size(), 30u);

  std::vector<Scene> scenes;
  scenes.reserve(files.size());
  for (const fs::path& f : files) scenes.push_back(loadScene(f));
  auto frameOf = [&](const Scene& scene) {
    try {
      return test::framePlanes(render(scene));
    } catch (const NotSupportedError&) {
      return std::string("not supported");  // e.g. more samples than the driver has
    }
  };
  std::vector<std::string> fresh(scenes.size());
  {
    const char* outer = std::getenv("RASTERCHECK_GL_CONTEXT");
    const std::string restore = outer != nullptr ? outer : "";
    ::setenv("RASTERCHECK_GL_CONTEXT", "new", 1);
    for (std::size_t i = 0; i < scenes.size(); ++i) fresh[i] = frameOf(scenes[i]);
    if (outer != nullptr) {
      ::setenv("RASTERCHECK_GL_CONTEXT", restore.c_str(), 1);
    } else {
      ::unsetenv("RASTERCHECK_GL_CONTEXT");
    }
  }
  std::vector<std::size_t> order(scenes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::mt19937 rng(7);
  std::shuffle(order.begin(), order.end(), rng);
  std::size_t previous = scenes.size() - 1;
  for (const std::size_t i : order) {
    EXPECT_TRUE(frameOf(scenes[i]) == fresh[i])
        << files[i].string() << " differs from its new-context frame when drawn after "
        << files[previous].string();
    previous = i;
  }
  // Lines and points once more, each right after a back-facing triangle (softpipe's set-up
  // hands its facing on: AReusedContextDrawsLinesWithTheFacingOfANewOne).
  const Scene back = backFacingQuad();
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    if (!drawsLinesOrPoints(scenes[i])) continue;
    render(back);
    EXPECT_TRUE(frameOf(scenes[i]) == fresh[i])
        << files[i].string() << " differs from its new-context frame after a back-facing quad";
  }
  fs::remove_all(dir);
}

// Programs are drawn through their binary (glGetProgramBinary, then glProgramBinary: the
// form every later process finds in Mesa's shader cache, so that a second run finds the
// first one's JIT-compiled variants; docs/performance.md "Mesa's shader cache"). That form
// must draw the bits the program linked from source draws: random scenes of every profile
// and the whole catalog, each both ways, every plane compared.
TEST_F(GlBackend, ProgramThroughItsBinaryDrawsTheSameBits) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("rc_binary_" + std::to_string(getpid()));
  const std::vector<fs::path> files = randomAndCatalog(dir, 20261332, 4);
  ASSERT_GE(files.size(), 30u);
  std::string driver;
  auto frameOf = [&](const Scene& scene, bool from_source, bool* binary) {
    HookGuard guard;
    gl::testing::hooks().program_from_source = from_source;
    try {
      const Frame f = render(scene);
      *binary = f.meta.at("program_binary").get<bool>();
      driver = f.meta.at("driver").get<std::string>();
      return test::framePlanes(f);
    } catch (const NotSupportedError&) {
      return std::string("not supported");
    }
  };
  // Mesa offers a binary format only where the driver has an on-disk shader cache
  // (llvmpipe, zink; not softpipe), and with that cache on.
  const char* disabled = std::getenv("MESA_SHADER_CACHE_DISABLE");
  const bool cache_on =
      disabled == nullptr || std::string(disabled) == "false" || std::string(disabled) == "0";
  int through_binary = 0;
  for (const fs::path& f : files) {
    const Scene scene = loadScene(f);
    bool binary = false;
    bool source_binary = true;
    const std::string a = frameOf(scene, false, &binary);
    const std::string b = frameOf(scene, true, &source_binary);
    if (a == "not supported") continue;
    EXPECT_FALSE(source_binary) << f.string();
    through_binary += binary ? 1 : 0;
    EXPECT_TRUE(a == b) << f.string() << ": the program's binary draws other bits than its source";
  }
  if (cache_on && (driver == "llvmpipe" || driver == "zink")) {
    EXPECT_GT(through_binary, 0) << "no render went through the program binary";
  }
  fs::remove_all(dir);
}

TEST_F(GlBackend, ReadbackWithAndWithoutPackInvertAgree) {
  for (ColorFormat color : {ColorFormat::RGBA32F, ColorFormat::RGBA8}) {
    for (DepthFormat depth : {DepthFormat::D16, DepthFormat::D24, DepthFormat::D32F}) {
      Scene s = orthoScene(24, 17);
      s.state.color_format = color;
      s.state.depth_format = depth;
      s.ambient_light = {0.1, 0.2, 0.3};
      Material m;
      m.ambient = {1, 0.5, 0.25};
      s.materials.push_back(m);
      Object o = quad(-0.9, -0.8, 0.7, 0.9, 0.1, 0);
      o.mesh.positions[2].z = -0.4f;
      o.mesh.positions[0].y = -0.2f;  // not symmetric top to bottom
      s.objects.push_back(o);
      const Frame a = render(s);
      Frame b;
      {
        HookGuard guard;
        gl::testing::hooks().ignore_pack_invert = true;
        b = render(s);
      }
      const std::string what = std::string(toString(color)) + "/" + toString(depth);
      EXPECT_EQ(a.color, b.color) << what;
      EXPECT_EQ(a.depth, b.depth) << what;
      EXPECT_EQ(a.id, b.id) << what;
      bool symmetric = true;
      for (int y = 0; y < 17; ++y)
        for (int x = 0; x < 24; ++x)
          symmetric = symmetric && a.id[a.index(x, y)] == a.id[a.index(x, 16 - y)];
      EXPECT_FALSE(symmetric) << "a flipped frame must look different";
    }
  }
}

TEST_F(GlBackend, ShaderCompileErrorSurfacesTheLog) {
  HookGuard guard;
  gl::testing::hooks().fragment_shader =
      "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(undeclared_thing_42); }\n";
  Scene s = orthoScene(4, 4);
  s.name = "gltest/broken-shader";
  try {
    render(s);
    FAIL() << "a broken shader rendered";
  } catch (const BackendError& e) {
    const std::string msg = e.what();
    EXPECT_THAT(msg, HasSubstr("gltest/broken-shader: " + toString(spec()) + ": "));
    EXPECT_THAT(msg, HasSubstr("fragment shader does not compile"));
    EXPECT_THAT(msg, HasSubstr("undeclared_thing_42"));  // the compiler's own log
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line";
  }
  // The real program still works afterwards.
  gl::testing::hooks() = gl::testing::Hooks{};
  EXPECT_NO_THROW(render(s));
}

TEST_F(GlBackend, GlErrorIsReportedWithItsStage) {
  HookGuard guard;
  gl::testing::hooks().gl_error_after_upload = true;
  Scene s = orthoScene(4, 4);
  s.name = "gltest/gl-error";
  try {
    render(s);
    FAIL() << "an invalid GL call went unnoticed";
  } catch (const BackendError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("GL error GL_INVALID_ENUM after upload"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("gltest/gl-error: "));
  }
  gl::testing::hooks() = gl::testing::Hooks{};
  EXPECT_NO_THROW(render(s));  // the error does not leak into the next call
}

// Death tests run in a fresh process ("threadsafe" style re-executes the binary), which
// is what these need: the driver is chosen by the first context of a process.
class GlProcess : public GlTest {
 protected:
  void SetUp() override {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    // The child re-runs SetUp; probing there would load the process spec's driver
    // before the statement under test picks one.
    if (GTEST_FLAG_GET(internal_run_death_test).empty()) GlTest::SetUp();
  }
  static std::string platformPrefix() {
    return spec().platform == GlSpec::Platform::OSMesa ? "gl:osmesa:" : "gl:egl:";
  }
};

[[noreturn]] void renderAndExit(const GlSpec& sp) {
  try {
    renderGl(orthoScene(2, 2), sp);
    std::_Exit(0);
  } catch (const BackendError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    std::_Exit(3);
  }
}

TEST_F(GlProcess, SubstitutedDriverIsABackendError) {
  if (spec().platform == GlSpec::Platform::EglDevice) GTEST_SKIP() << "no Gallium driver choice";
  EXPECT_EXIT(
      {
        gl::testing::hooks().gallium_driver = "llvmpipe";           // Mesa loads llvmpipe...
        renderAndExit(parseGlSpec(platformPrefix() + "softpipe"));  // ...softpipe was asked
      },
      ::testing::ExitedWithCode(3), "asked for softpipe, GL_RENDERER is llvmpipe");
}

TEST_F(GlProcess, ZinkSubstitutedIsABackendErrorNamingWhatLoaded) {
  if (spec().platform != GlSpec::Platform::EglSurfaceless) GTEST_SKIP() << "zink is EGL only";
  EXPECT_EXIT(
      {
        gl::testing::hooks().gallium_driver = "llvmpipe";  // Mesa loads llvmpipe...
        renderAndExit(parseGlSpec("gl:egl:zink"));         // ...zink was asked
      },
      ::testing::ExitedWithCode(3), "asked for zink, GL_RENDERER is llvmpipe \\(LLVM");
}

TEST_F(GlProcess, SecondDriverInOneProcessIsRefused) {
  if (spec().platform == GlSpec::Platform::EglDevice) GTEST_SKIP() << "no Gallium driver choice";
  EXPECT_EXIT(
      {
        renderGl(orthoScene(2, 2), parseGlSpec(platformPrefix() + "llvmpipe"));
        renderAndExit(parseGlSpec(platformPrefix() + "softpipe"));
      },
      ::testing::ExitedWithCode(3), "already loaded llvmpipe");
}

TEST_F(GlProcess, DefaultDriverIsWhatGalliumDriverSays) {
  if (spec().platform == GlSpec::Platform::EglDevice) GTEST_SKIP() << "no Gallium driver choice";
  EXPECT_EXIT(
      {
        setenv("GALLIUM_DRIVER", "softpipe", 1);
        const Frame f =
            renderGl(orthoScene(2, 2),
                     parseGlSpec(spec().platform == GlSpec::Platform::OSMesa ? "gl:osmesa" : "gl"));
        std::fprintf(stderr, "driver=%s\n", f.meta.at("driver").get<std::string>().c_str());
        std::_Exit(0);
      },
      ::testing::ExitedWithCode(0), "driver=softpipe");
}

TEST_F(GlBackend, BadInputNeverCrashes) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Scene s = orthoScene(8, 8);
  s.ambient_light = glm::dvec3(1.0);
  Material m;
  m.ambient = {1, 1, 1};
  s.materials.push_back(m);
  Object nan_quad = quad(-2, -2, 2, 2, 0, 0);
  nan_quad.mesh.positions[3].x = nan;  // only triangle (0, 2, 3) uses vertex 3
  s.objects.push_back(nan_quad);
  Object empty;
  s.objects.push_back(empty);
  Object degenerate;
  degenerate.mesh.positions.assign(3, glm::vec3(0.1f, 0.1f, 0.0f));
  degenerate.mesh.normals.assign(3, glm::vec3(0, 0, 1));
  degenerate.mesh.triangles = {{0, 1, 2}};
  s.objects.push_back(degenerate);
  // Finite but far outside the view, behind the rest: GL's clipper must cope.
  s.objects.push_back(quad(-1e30, -1e30, 1e30, 1e30, -0.9, 0));  // ids 4, 5
  Object inf;
  inf.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, std::numeric_limits<float>::infinity(), 0}};
  inf.mesh.normals.assign(3, glm::vec3(0, 0, 1));
  inf.mesh.triangles = {{0, 1, 2}};  // id 6
  s.objects.push_back(inf);
  const Frame f = render(s);
  EXPECT_EQ(f.meta.at("skipped_triangles"), 2);  // the NaN triangle and the infinite one
  const std::set<std::uint32_t> ids(f.id.begin(), f.id.end());
  EXPECT_EQ(ids.count(1), 1u);                 // the finite half of the NaN quad
  EXPECT_EQ(ids.count(2), 0u);                 // its NaN half
  EXPECT_EQ(ids.count(3), 0u);                 // the degenerate triangle covers nothing
  EXPECT_EQ(ids.count(4) + ids.count(5), 1u);  // the huge quad shows where id 2 is missing
  EXPECT_EQ(ids.count(6), 0u);
  for (float c : f.color) ASSERT_TRUE(std::isfinite(c));
}

TEST_F(GlBackend, TinyAndAbsurdSizes) {
  Scene one = orthoScene(1, 1);
  one.materials.push_back(Material{});
  one.objects.push_back(quad(-2, -2, 2, 2, 0, 0));
  const Frame f = render(one);
  EXPECT_EQ(f.pixelCount(), 1u);
  EXPECT_NE(f.id[0], 0u);

  Scene absurd = orthoScene(1000000, 1000000);
  absurd.name = "gltest/absurd";
  try {
    render(absurd);
    FAIL() << "a 10^12-pixel frame rendered";
  } catch (const BackendError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("gltest/absurd: "));
    EXPECT_THAT(std::string(e.what()), HasSubstr("exceeds"));
  }
  EXPECT_THROW(render(orthoScene(0, 4)), InputError);
  EXPECT_THROW(render(orthoScene(4, -1)), InputError);
}

TEST_F(GlBackend, InconsistentScenesAreInputErrors) {
  Scene s = orthoScene(4, 4);
  s.materials.push_back(Material{});
  Object o = quad(-1, -1, 1, 1, 0, 0);
  o.material = 7;
  s.objects.push_back(o);
  EXPECT_THROW(render(s), InputError);
  s.objects[0].material = 0;
  s.objects[0].mesh.triangles.push_back({0, 1, 9});
  EXPECT_THROW(render(s), InputError);
  s.objects[0].mesh.triangles.pop_back();
  s.objects[0].mesh.normals.pop_back();
  EXPECT_THROW(render(s), InputError);
  s.objects[0].mesh.normals.emplace_back(0, 0, 1);
  auto bad = std::make_shared<Texture>();
  bad->width = 4;
  bad->height = 4;  // but no texels
  s.materials[0].texture = bad;
  EXPECT_THROW(render(s), InputError);
  s.materials[0].texture = nullptr;
  EXPECT_NO_THROW(render(s));
}

}  // namespace
}  // namespace rc::gltest
