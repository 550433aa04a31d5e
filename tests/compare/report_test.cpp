// The report writers, read back by independent consumers: report.json against
// docs/report-schema.json with Python's jsonschema, junit.xml with pugixml, report.html
// in headless Chromium (every row rendered, every image loaded), the images with OIIO.
// Also all-or-nothing writes and exit codes.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include "compare/pair_images.h"
#include "compare/report.h"
#include "fixtures/errors.h"
#include "synthetic_frames.h"

namespace rc {
namespace {
namespace fs = std::filesystem;

constexpr int kW = 96;
constexpr int kH = 64;
// Inside the back rectangle at 96x64 (x 4.8..57.6, y 5.1..44.8), above its diagonal.
constexpr int kBx0 = 26, kBy0 = 7, kBx1 = 36, kBy1 = 12;  // 10 x 5 = 50 px
constexpr std::uint64_t kBlock = 50;

fs::path freshDir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_report_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<fs::path> tempLeftovers(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) out.push_back(e.path());
  return out;
}

// A small run: one pass, one warn, one fail (two fixtures, two backends) and one error row.
class ReportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    out_ = new fs::path(freshDir("suite"));
    report_ = new Report;
    report_->tool_version = "0.1.0-test";
    report_->command = "rastercheck run <tests> --backends a,b";
    Frame ref = testing::renderRects(kW, kH, testing::defaultRects(kW, kH));
    const Tolerances tol = tolerancesForFrames(ref, ref);

    auto add = [&](Frame actual, const std::string& fixture, const std::string& backend) {
      actual.clearUncertainty();
      actual.meta["backend"] = backend;
      Frame expected = ref;
      expected.meta["fixture"] = fixture;
      ClassMaps maps;
      maps.want_flip = true;  // FLIP is opt-in (`--flip`): these pairs ask for it
      PairResult r = compareFrames(expected, actual, expected, tol, &maps);
      writePairImages(expected, actual, maps, pairDirectory(*out_, r), r);
      report_->results.push_back(r);
    };
    add(ref, "synthetic/a", "gl:egl:llvmpipe");
    Frame warn = ref;  // shading 0.3 units: above warn + allowance, below fail + allowance
    for (int y = kBy0; y < kBy1; ++y)
      for (int x = kBx0; x < kBx1; ++x) warn.color[warn.index(x, y) * 4] += 0.3f / 255.0f;
    add(warn, "synthetic/a", "gl:egl:softpipe");
    Frame fail = ref;
    for (int y = kBy0; y < kBy1; ++y)
      for (int x = kBx0; x < kBx1; ++x) fail.id[fail.index(x, y)] = 0;
    add(fail, "synthetic/b", "gl:egl:llvmpipe");
    report_->results.push_back(
        errorResult("synthetic/b", "ref", "gl:egl:softpipe", "EGL: no display <&> \"here\""));
    writeReport(*report_, *out_);
  }
  static void TearDownTestSuite() {
    // RC_KEEP_OUTPUT=1 keeps the report for people to look at.
    if (std::getenv("RC_KEEP_OUTPUT"))
      std::printf("report kept in %s\n", out_->c_str());
    else if (!::testing::Test::HasFailure())
      fs::remove_all(*out_);
    delete out_;
    delete report_;
  }

  static fs::path* out_;
  static Report* report_;
};
fs::path* ReportTest::out_ = nullptr;
Report* ReportTest::report_ = nullptr;

TEST_F(ReportTest, RowsHaveTheExpectedVerdicts) {
  ASSERT_EQ(report_->results.size(), 4u);
  EXPECT_EQ(report_->results[0].status, Status::Pass);
  EXPECT_EQ(report_->results[1].status, Status::Warn);
  EXPECT_EQ(report_->results[1].shading.status, Status::Warn);
  EXPECT_EQ(report_->results[2].status, Status::Fail);
  EXPECT_EQ(report_->results[2].visibility.missing_hard, kBlock);
  EXPECT_EQ(report_->results[3].status, Status::Error);
  const ReportSummary s = report_->summary();
  EXPECT_EQ(s.pass, 1u);
  EXPECT_EQ(s.warn, 1u);
  EXPECT_EQ(s.fail, 1u);
  EXPECT_EQ(s.error, 1u);
}

TEST_F(ReportTest, EveryFileIsWrittenAndNoTemporaryRemains) {
  for (const char* f : {"report.json", "junit.xml", "report.html"})
    EXPECT_TRUE(fs::is_regular_file(*out_ / f)) << f;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(report_->results[k].images.size(), 7u);  // with flip_heat.png
    for (const auto& [kind, file] : report_->results[k].images)
      EXPECT_TRUE(fs::is_regular_file(file)) << kind << ": " << file;
  }
  EXPECT_TRUE(tempLeftovers(*out_).empty());
}

TEST_F(ReportTest, JsonHoldsTheContractFields) {
  const nlohmann::json j = nlohmann::json::parse(readText(*out_ / "report.json"));
  EXPECT_EQ(j.at("tool").at("name"), "rastercheck");
  EXPECT_EQ(j.at("tool").at("version"), "0.1.0-test");
  EXPECT_EQ(j.at("summary").at("pass"), 1);
  EXPECT_EQ(j.at("summary").at("error"), 1);
  EXPECT_EQ(j.at("exit_code"), 3);
  const nlohmann::json& fail = j.at("results").at(2);
  EXPECT_EQ(fail.at("status"), "fail");
  EXPECT_EQ(fail.at("visibility").at("missing"), kBlock);
  EXPECT_EQ(fail.at("pixels"), kW * kH);
  const int wx = fail.at("visibility").at("worst").at(0);
  const int wy = fail.at("visibility").at("worst").at(1);
  EXPECT_TRUE(wx >= kBx0 && wx < kBx1 && wy >= kBy0 && wy < kBy1);
  EXPECT_EQ(fail.at("visibility").at("worst_window").at(0), wx);
  EXPECT_EQ(fail.at("visibility").at("worst_window").at(1), kH - 1 - wy);
  EXPECT_EQ(j.at("results").at(0).at("shading").at("psnr_db"), kPsnrCapDb);  // identical: the cap
  EXPECT_LT(j.at("results").at(1).at("shading").at("psnr_db"), kPsnrCapDb);
  const nlohmann::json& error = j.at("results").at(3);
  EXPECT_EQ(error.at("error"), "EGL: no display <&> \"here\"");
  // An error row has the contract's shape: every class "error", nothing compared.
  for (const char* cls : {"visibility", "depth", "shading"}) {
    EXPECT_EQ(error.at(cls).at("status"), "error") << cls;
    // at() throws (a failed test) where const operator[] would read a missing key: undefined.
    EXPECT_TRUE(!error.at(cls).contains("worst") || error.at(cls).at("worst").is_null()) << cls;
  }
  EXPECT_EQ(error.at("visibility").at("mismatched"), 0);
  EXPECT_EQ(error.at("depth").at("compared"), 0);
  EXPECT_EQ(error.at("shading").at("compared"), 0);
  EXPECT_TRUE(error.at("images").is_object() && error.at("images").empty());
  // The additive perceptual blocks: flip where asked for, ciede2000 on every compared pair
  // (identical colours: all zero), neither on an error row.
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_TRUE(j.at("results").at(k).contains("flip")) << k;
    EXPECT_TRUE(j.at("results").at(k).contains("ciede2000")) << k;
  }
  EXPECT_EQ(j.at("results").at(0).at("ciede2000").at("differing"), 0);
  EXPECT_EQ(j.at("results").at(0).at("ciede2000").at("max"), 0.0);
  EXPECT_TRUE(j.at("results").at(0).at("ciede2000").at("worst").is_null());
  EXPECT_FALSE(error.contains("flip"));
  EXPECT_FALSE(error.contains("ciede2000"));
  // Image paths are relative to the report and resolve there.
  for (const auto& [kind, rel] : fail.at("images").items()) {
    EXPECT_FALSE(fs::path(rel.get<std::string>()).is_absolute()) << kind;
    EXPECT_TRUE(fs::is_regular_file(*out_ / rel.get<std::string>())) << kind;
  }
  // Histogram counts add up to the compared pixels.
  std::uint64_t total = 0;
  for (const auto& c : j.at("results").at(1).at("shading").at("histogram").at("counts"))
    total += c.get<std::uint64_t>();
  EXPECT_EQ(total, j.at("results").at(1).at("shading").at("compared"));
}

int validate(const fs::path& report) {
  const std::string cmd =
      "/usr/bin/python3 -c \"import json,sys,jsonschema; "
      "jsonschema.validate(json.load(open(sys.argv[1])), "
      "json.load(open(sys.argv[2])))\" '" +
      report.string() + "' '" RC_SOURCE_DIR "/docs/report-schema.json' 2>&1";
  return std::system(cmd.c_str());
}

TEST_F(ReportTest, JsonValidatesAgainstTheSchema) {
  if (std::system("/usr/bin/python3 -c 'import jsonschema' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-jsonschema is not installed";
  EXPECT_EQ(validate(*out_ / "report.json"), 0);
  // The schema must be able to say no.
  nlohmann::json j = nlohmann::json::parse(readText(*out_ / "report.json"));
  const fs::path bad = *out_ / "bad.json";
  j["results"][0]["status"] = "maybe";
  std::ofstream(bad) << j.dump();
  EXPECT_NE(validate(bad), 0);
  j = nlohmann::json::parse(readText(*out_ / "report.json"));
  j["results"][2]["depth"].erase("max_steps");
  std::ofstream(bad) << j.dump();
  EXPECT_NE(validate(bad), 0);
  j = nlohmann::json::parse(readText(*out_ / "report.json"));
  j["results"][3]["visibility"] = j["results"][2]["visibility"];  // an error row compared nothing
  std::ofstream(bad) << j.dump();
  EXPECT_NE(validate(bad), 0);
  j = nlohmann::json::parse(readText(*out_ / "report.json"));
  j["results"][3].erase("shading");  // ... but has every class
  std::ofstream(bad) << j.dump();
  EXPECT_NE(validate(bad), 0);
  j = nlohmann::json::parse(readText(*out_ / "report.json"));
  j["results"][0]["shading"]["psnr_db"] = nullptr;  // always a number
  std::ofstream(bad) << j.dump();
  EXPECT_NE(validate(bad), 0);
  fs::remove(bad);
}

TEST_F(ReportTest, JunitHasOneTestcasePerPairWithReasons) {
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file((*out_ / "junit.xml").c_str()));
  const pugi::xml_node suite = doc.child("testsuites").child("testsuite");
  EXPECT_EQ(suite.attribute("tests").as_int(), 4);
  EXPECT_EQ(suite.attribute("failures").as_int(), 1);
  EXPECT_EQ(suite.attribute("errors").as_int(), 1);
  std::vector<pugi::xml_node> cases;
  for (pugi::xml_node tc : suite.children("testcase")) cases.push_back(tc);
  ASSERT_EQ(cases.size(), 4u);
  EXPECT_STREQ(cases[0].attribute("classname").value(), "synthetic/a");
  EXPECT_STREQ(cases[0].attribute("name").value(), "ref vs gl:egl:llvmpipe");
  EXPECT_FALSE(cases[0].child("failure"));
  EXPECT_FALSE(cases[1].child("failure"));  // a warning passes...
  EXPECT_NE(std::string(cases[1].child_value("system-out")).find("WARN"), std::string::npos);
  EXPECT_NE(std::string(cases[1].child_value("system-out")).find("shading warn"),
            std::string::npos);
  const pugi::xml_node failure = cases[2].child("failure");
  ASSERT_TRUE(failure);
  const std::string message = failure.attribute("message").value();
  EXPECT_NE(message.find("visibility fail"), std::string::npos) << message;
  EXPECT_NE(message.find(std::to_string(kBlock) + " hard"), std::string::npos) << message;
  const PixelRef w = report_->results[2].visibility.worst;
  const std::string at = "(" + std::to_string(w.x) + "," + std::to_string(w.y) + ") window (" +
                         std::to_string(w.x) + "," + std::to_string(kH - 1 - w.y) + ")";
  EXPECT_NE(message.find(at), std::string::npos) << message;
  EXPECT_STREQ(failure.attribute("type").value(), "visibility");
  const pugi::xml_node error = cases[3].child("error");
  ASSERT_TRUE(error);
  EXPECT_STREQ(error.attribute("message").value(), "EGL: no display <&> \"here\"");
}

struct PageState {
  int rows = -1, pairs = -1, images_ok = -1, images_failed = -1;
  bool ready = false;
};

// `hash` (e.g. "#open-all": every pair opened, so every image loads) goes on the URL.
PageState renderInChromium(const fs::path& html, const std::string& hash = "") {
  const fs::path profile = freshDir("chromium_profile");
  const fs::path dom = freshDir("dom").string() + ".html";
  const std::string cmd =
      "timeout 120 /usr/bin/chromium --headless --no-sandbox --disable-gpu "
      "--disable-background-networking --disable-component-update --disable-sync "
      "--no-first-run --allow-file-access-from-files --virtual-time-budget=10000 "
      "--user-data-dir='" +
      profile.string() + "' --dump-dom 'file://" + fs::absolute(html).string() + hash + "' > '" +
      dom.string() + "' 2>/dev/null";
  const int rc = std::system(cmd.c_str());
  PageState s;
  const std::string text = readText(dom);
  fs::remove_all(profile);
  fs::remove(dom);
  if (rc != 0) return s;
  std::smatch m;
  const std::regex body("<body([^>]*)>");
  if (!std::regex_search(text, m, body)) return s;
  const std::string attrs = m[1];
  auto attr = [&](const char* name) {
    std::smatch a;
    if (std::regex_search(attrs, a, std::regex(std::string(name) + "=\"(\\d+)\"")))
      return std::stoi(a[1]);
    return -1;
  };
  s.rows = attr("data-rows-rendered");
  s.pairs = attr("data-pairs-rendered");
  s.images_ok = attr("data-images-ok");
  s.images_failed = attr("data-images-failed");
  s.ready = attr("data-ready") == 1;
  return s;
}

TEST_F(ReportTest, HtmlRendersEveryRowAndLoadsEveryImageInChromium) {
  if (!fs::exists("/usr/bin/chromium")) GTEST_SKIP() << "/usr/bin/chromium is not installed";
  // Images load when their pair is opened: the two pairs that did not pass are open.
  const PageState first = renderInChromium(*out_ / "report.html");
  ASSERT_TRUE(first.ready) << "the page's script did not finish";
  EXPECT_EQ(first.rows, 4);
  EXPECT_EQ(first.pairs, 4);
  EXPECT_EQ(first.images_ok, 2 * 6);  // five maps and pictures plus the FLIP map
  EXPECT_EQ(first.images_failed, 0);
  const PageState s = renderInChromium(*out_ / "report.html", "#open-all");
  ASSERT_TRUE(s.ready) << "the page's script did not finish";
  EXPECT_EQ(s.rows, 4);
  EXPECT_EQ(s.pairs, 4);
  // expected, actual, visibility, two heat maps and the FLIP map per pair
  EXPECT_EQ(s.images_ok, 3 * 6);
  EXPECT_EQ(s.images_failed, 0);

  // The check can fail: a copy of the page whose one image is missing.
  const fs::path copy = freshDir("broken");
  fs::copy(*out_, copy, fs::copy_options::recursive);
  fs::remove(pairDirectory(copy, report_->results[1]) / "depth_heat.png");
  const PageState broken = renderInChromium(copy / "report.html", "#open-all");
  fs::remove_all(copy);
  EXPECT_EQ(broken.images_ok, 3 * 6 - 1);
  EXPECT_EQ(broken.images_failed, 1);
}

TEST_F(ReportTest, HtmlIsSelfContained) {
  const std::string html = readText(*out_ / "report.html");
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_NE(html.find("EGL: no display &lt;&amp;&gt; &quot;here&quot;"), std::string::npos);
  EXPECT_NE(html.find("Fixture &times; backend"), std::string::npos);  // two backends: matrix
}

TEST_F(ReportTest, ImagesShowTheClassesAndDiffExrHoldsTheNumbers) {
  const PairResult& fail = report_->results[2];
  auto visibility = OIIO::ImageInput::open(fail.images.at("visibility").string());
  ASSERT_TRUE(visibility);
  EXPECT_EQ(visibility->spec().width, kW);
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(kW) * kH * 3);
  ASSERT_TRUE(visibility->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb.data()));
  const std::size_t in_block = static_cast<std::size_t>(kBy0) * kW + kBx0;
  const Rgb8 hard = classColor(PixelClass::MissingHard);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[in_block * 3 + c], hard[c]);
  EXPECT_EQ(rgb[0], classColor(PixelClass::Background)[0]);

  // EXR keeps channels sorted by name, so readers go by name.
  auto diff = OIIO::ImageInput::open(fail.images.at("diff_exr").string());
  ASSERT_TRUE(diff);
  const OIIO::ImageSpec spec = diff->spec();
  constexpr int kChannels = 9;
  ASSERT_EQ(spec.nchannels, kChannels);
  const int id_class = spec.channelindex("id_class");
  const int depth_steps = spec.channelindex("depth_steps");
  const int shading_abs = spec.channelindex("shading_abs");
  const int d_r = spec.channelindex("dR");
  const int d_g = spec.channelindex("dG");
  const int shading_tolerance = spec.channelindex("shading_tolerance");
  for (const char* name : {"id_class", "depth_steps", "depth_tolerance", "shading_abs",
                           "shading_tolerance", "dR", "dG", "dB", "dA"})
    EXPECT_GE(spec.channelindex(name), 0) << name;
  std::vector<float> px(static_cast<std::size_t>(kW) * kH * kChannels);
  ASSERT_TRUE(diff->read_image(0, 0, 0, kChannels, OIIO::TypeDesc::FLOAT, px.data()));
  EXPECT_EQ(px[in_block * kChannels + id_class], static_cast<float>(PixelClass::MissingHard));
  EXPECT_EQ(px[in_block * kChannels + depth_steps], 0.0f);

  const PairResult& warn = report_->results[1];
  auto wdiff = OIIO::ImageInput::open(warn.images.at("diff_exr").string());
  ASSERT_TRUE(wdiff && wdiff->read_image(0, 0, 0, kChannels, OIIO::TypeDesc::FLOAT, px.data()));
  EXPECT_EQ(px[in_block * kChannels + id_class], static_cast<float>(PixelClass::Match));
  EXPECT_NEAR(px[in_block * kChannels + shading_abs], 0.3f, 1e-4);
  EXPECT_NEAR(px[in_block * kChannels + d_r], 0.3f, 1e-4);  // (actual - expected) * 255
  EXPECT_EQ(px[in_block * kChannels + d_g], 0.0f);
  // Over warn there, so its tolerance is kept: warn + allowance, below the error.
  EXPECT_GT(px[in_block * kChannels + shading_tolerance], warn.tolerances.shading.warn);
  EXPECT_LT(px[in_block * kChannels + shading_tolerance], 0.3f);
  EXPECT_DOUBLE_EQ(warn.shading_heat_scale,
                   std::max({warn.shading.max_abs, warn.tolerances.shading.fail, 1.0}));
}

TEST(ReportWrite, NothingIsLeftWhenAFileCannotBeWritten) {
  const fs::path out = freshDir("blocked");
  fs::create_directories(out / "junit.xml");  // a folder where a file must go
  Report report;
  report.results.push_back(errorResult("f", "ref", "gl", "x"));
  EXPECT_THROW(writeReport(report, out), InputError);
  EXPECT_FALSE(fs::exists(out / "report.json"));
  EXPECT_FALSE(fs::exists(out / "report.html"));
  EXPECT_TRUE(tempLeftovers(out).empty());

  // Images into a path that is a file.
  Frame f = testing::renderRects(8, 8, testing::defaultRects(8, 8));
  ClassMaps maps;
  PairResult r = compareFrames(f, f, f, tolerancesForFrames(f, f), &maps);
  std::ofstream(out / "file") << "x";
  EXPECT_THROW(writePairImages(f, f, maps, out / "file", r), InputError);
  EXPECT_TRUE(r.images.empty());
  // Maps that do not match the frames.
  maps.shading_abs.pop_back();
  EXPECT_THROW(writePairImages(f, f, maps, out / "pair", r), InputError);
  EXPECT_FALSE(fs::exists(out / "pair" / "expected.png"));
  fs::remove_all(out);
}

// The per-backend table of report.html counts every status, not_supported too (it was
// indexed past a table of four: a heap overflow under ASan, a wrong count without).
TEST(ReportHtml, BackendCountsIncludeNotSupported) {
  Report report;
  PairResult pass;
  pass.fixture = "f1";
  pass.expected = "ref";
  pass.actual = "gl:a";
  report.results = {pass, notSupportedResult("f2", "ref", "gl:a", "4 samples"),
                    notSupportedResult("f1", "ref", "gl:b", "4 samples"),
                    notSupportedResult("f2", "ref", "gl:b", "4 samples"),
                    errorResult("f3", "ref", "gl:b", "no driver")};
  const std::string html = reportHtml(report, freshDir("not_supported"));
  const std::size_t table = html.find("<table id=\"backends\">");
  ASSERT_NE(table, std::string::npos);
  const std::string counts = html.substr(table, html.find("</table>", table) - table);
  EXPECT_NE(counts.find("<th>not supported</th>"), std::string::npos) << counts;
  EXPECT_NE(counts.find("<tr><td>gl:a</td><td class=\"n\">1</td><td class=\"n\">0</td>"
                        "<td class=\"n\">0</td><td class=\"n\">0</td><td class=\"n\">1</td>"),
            std::string::npos)
      << counts;
  EXPECT_NE(counts.find("<tr><td>gl:b</td><td class=\"n\">0</td><td class=\"n\">0</td>"
                        "<td class=\"n\">0</td><td class=\"n\">1</td><td class=\"n\">2</td>"),
            std::string::npos)
      << counts;
}

TEST(ReportExit, CodesFollowTheWorstRow) {
  Report report;
  EXPECT_EQ(exitCodeFor(report), 0);
  PairResult pass;
  PairResult warn;
  warn.status = Status::Warn;
  PairResult fail;
  fail.status = Status::Fail;
  report.results = {pass, warn};
  EXPECT_EQ(exitCodeFor(report), 0);
  report.results.push_back(fail);
  EXPECT_EQ(exitCodeFor(report), 1);
  report.results.push_back(errorResult("f", "ref", "gl", "no driver"));
  EXPECT_EQ(exitCodeFor(report), 3);
}

TEST(ReportText, DescribeNamesTheFailingClassAndItsNumbers) {
  Frame ref = testing::renderRects(64, 64, testing::defaultRects(64, 64));
  Frame gl = ref;
  gl.meta["backend"] = "gl:x";
  const std::size_t i = gl.index(20, 10);
  gl.depth[i] = static_cast<float>(gl.depth[i] + 500.0 / 16777215.0);
  const PairResult r = compareFrames(ref, gl, ref, tolerancesForFrames(ref, gl));
  ASSERT_EQ(r.status, Status::Fail);
  const std::string text = describe(r);
  EXPECT_EQ(text.rfind("FAIL synthetic/rects ref vs gl:x: depth fail: 1 px over tolerance", 0), 0u)
      << text;
  EXPECT_NE(text.find("(20,10) window (20,53)"), std::string::npos) << text;
  EXPECT_EQ(text.find("visibility"), std::string::npos) << text;  // passing classes stay out
  EXPECT_EQ(describe(compareFrames(ref, ref, ref, tolerancesForFrames(ref, ref))),
            "PASS synthetic/rects ref vs ref");
}

// The heat legend's colour map is kept in the user cache (fixtures/shared_cache.h), so that
// report.html of a run that wrote no image loads no image library: the stops are
// OpenImageIO's, an entry changed on disk is what a later call gets, and without the cache
// the map is OpenImageIO's again.
TEST(ColorStops, TheUserCacheKeepsOpenImageIOsMap) {
  const std::filesystem::path user =
      std::filesystem::temp_directory_path() / ("rc_color_stops_" + std::to_string(::getpid()));
  std::filesystem::remove_all(user);
  ::setenv("RASTERCHECK_CACHE_DISABLE", "1", 1);
  const std::vector<Rgb8> plain = colorStops(9, kHeatColorMap);
  ::unsetenv("RASTERCHECK_CACHE_DISABLE");
  ::setenv("RASTERCHECK_CACHE_DIR", user.c_str(), 1);
  EXPECT_EQ(colorStops(9, kHeatColorMap), plain);
  std::vector<std::filesystem::path> entries;
  for (const auto& e : std::filesystem::directory_iterator(user)) entries.push_back(e.path());
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0].extension(), ".rcmap");
  {
    std::fstream f(entries[0], std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-4, std::ios::end);  // the last stop's blue, a float
    const float zero = 0.0f;
    f.write(reinterpret_cast<const char*>(&zero), sizeof zero);
  }
  const std::vector<Rgb8> cached = colorStops(9, kHeatColorMap);
  ASSERT_EQ(cached.size(), plain.size());
  EXPECT_EQ(cached.back()[2], 0);
  EXPECT_NE(plain.back()[2], 0);
  EXPECT_EQ(colorStops(5, kHeatColorMap).size(), 5u);  // another count: another entry
  ::setenv("RASTERCHECK_CACHE_DISABLE", "1", 1);
  EXPECT_EQ(colorStops(9, kHeatColorMap), plain);
  ::unsetenv("RASTERCHECK_CACHE_DISABLE");
  ::unsetenv("RASTERCHECK_CACHE_DIR");
  std::filesystem::remove_all(user);
}

// Pair images go through the user cache too (compare/pair_images.cpp): a pair that fails in
// the same way as before has its visibility map, heat maps and diff.exr copied from there
// (an entry changed on disk is what the next write gives), they are the encoder's bytes, and
// a pair with other errors is other keys, encoded again.
TEST(PairImages, TheUserCacheServesPairImagesWrittenBefore) {
  const fs::path dir = freshDir("pair_image_cache");
  const fs::path user = dir / "user";
  // The variables back as they were whichever way the test ends (the binary's other tests).
  struct Unset {
    Unset() = default;
    Unset(const Unset&) = delete;
    Unset& operator=(const Unset&) = delete;
    ~Unset() {
      ::unsetenv("RASTERCHECK_CACHE_DIR");
      ::unsetenv("RASTERCHECK_CACHE_DISABLE");
    }
  } unset;
  Frame ref = testing::renderRects(kW, kH, testing::defaultRects(kW, kH));
  ref.meta["fixture"] = "synthetic/cached";
  auto failing = [&](std::uint32_t id) {
    Frame f = ref;
    f.clearUncertainty();
    f.meta["backend"] = "gl:egl:llvmpipe";
    for (int y = kBy0; y < kBy1; ++y)
      for (int x = kBx0; x < kBx1; ++x) f.id[f.index(x, y)] = id;
    return f;
  };
  auto write = [&](const Frame& actual, const fs::path& out) {
    ClassMaps maps;
    PairResult r = compareFrames(ref, actual, ref, tolerancesForFrames(ref, actual), &maps);
    EXPECT_EQ(r.status, Status::Fail);
    writePairImages(ref, actual, maps, out, r);
  };
  const std::vector<std::string> names = {"visibility.png", "depth_heat.png", "shading_heat.png",
                                          "diff.exr"};
  auto bytes = [](const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  auto entries = [&] {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(user))
      if (e.path().extension() == ".rcpair") out.push_back(e.path());
    return out;
  };
  ::setenv("RASTERCHECK_CACHE_DISABLE", "1", 1);
  write(failing(0), dir / "plain");
  write(failing(7), dir / "plain7");
  ::unsetenv("RASTERCHECK_CACHE_DISABLE");
  ::setenv("RASTERCHECK_CACHE_DIR", user.c_str(), 1);
  write(failing(0), dir / "a");
  for (const std::string& n : names) EXPECT_EQ(bytes(dir / "a" / n), bytes(dir / "plain" / n)) << n;
  // One entry per distinct file (the two heat maps of a pair whose errors are all visibility
  // are the same picture).
  std::set<std::string> distinct;
  for (const std::string& n : names) distinct.insert(bytes(dir / "a" / n));
  const std::vector<fs::path> made = entries();
  ASSERT_EQ(made.size(), distinct.size());
  std::vector<std::string> originals;
  for (const fs::path& e : made) {  // every entry's last byte flipped
    originals.push_back(bytes(e));
    std::string b = originals.back();
    b.back() = static_cast<char>(b.back() ^ 0x5a);
    std::ofstream(e, std::ios::binary | std::ios::trunc) << b;
  }
  write(failing(0), dir / "b");
  for (const std::string& n : names) {
    const std::string served = bytes(dir / "b" / n);
    const std::string plain = bytes(dir / "plain" / n);
    ASSERT_EQ(served.size(), plain.size()) << n;
    EXPECT_EQ(served.back(), static_cast<char>(plain.back() ^ 0x5a)) << n;
  }
  for (std::size_t k = 0; k < made.size(); ++k)
    std::ofstream(made[k], std::ios::binary | std::ios::trunc) << originals[k];
  write(failing(7), dir / "c");  // other ids: other images, other keys
  for (const std::string& n : names) distinct.insert(bytes(dir / "c" / n));
  EXPECT_EQ(entries().size(), distinct.size());
  EXPECT_GT(distinct.size(), made.size());
  for (const std::string& n : names)
    EXPECT_EQ(bytes(dir / "c" / n), bytes(dir / "plain7" / n)) << n;
  ::unsetenv("RASTERCHECK_CACHE_DIR");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rc
