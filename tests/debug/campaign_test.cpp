// debug/campaign.h: failures read from report rows, signatures, groups, the summary
// files and the exit code, on hand-written reports (no rendering).
#include "debug/campaign.h"

#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fixtures/errors.h"

namespace rc {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

json row(const std::string& fixture, const std::string& actual, const std::string& status,
         const std::string& vis = "pass", const std::string& depth = "pass",
         const std::string& shading = "pass") {
  return {{"fixture", fixture},
          {"expected", "ref"},
          {"actual", actual},
          {"status", status},
          {"visibility",
           {{"status", vis},
            {"hard", 7},
            {"missing_hard", 1},
            {"extra_hard", 2},
            {"wrong_primitive_hard", 4},
            {"worst", {3, 4}}}},
          {"depth",
           {{"status", depth},
            {"over_tolerance", 12},
            {"max_steps", 40.5},
            {"worst", {1, 2}},
            {"worst_steps", 40.5},
            {"worst_allowance", 1.23456789}}},
          {"shading", {{"status", shading}, {"over_tolerance", 0}, {"max_abs", 0.1}}},
          {"images",
           {{"expected", "pairs/" + fixture + "/ref_vs_x/expected.png"},
            {"actual", "pairs/" + fixture + "/ref_vs_x/actual.png"}}}};
}

json report(std::vector<json> rows) { return {{"results", rows}}; }

FixtureInfo info(const std::string& name) {
  return {"/scenes/" + name + ".json", {"random", "depth_format:d16", "tag:" + name}};
}

std::vector<CampaignFailure> read(const json& r) {
  return failuresOfReport(r, "runs/00000-00009", info, "report.json");
}

TEST(CampaignFailures, OneFailurePerFailingClassAndOneForAnError) {
  json err = {{"fixture", "c"},
              {"expected", "ref"},
              {"actual", "gl:egl:softpipe"},
              {"status", "error"},
              {"error", "c: gl:egl:softpipe: crashed (Segmentation fault)"}};
  const auto failures =
      read(report({row("a", "gl:egl:llvmpipe", "pass"), row("w", "gl:egl:llvmpipe", "warn", "warn"),
                   row("b", "gl:egl:softpipe", "fail", "fail", "fail"), err}));
  ASSERT_EQ(failures.size(), 3u);
  EXPECT_EQ(failures[0].id, "b__gl_egl_softpipe__visibility");
  EXPECT_EQ(failures[0].cls, "visibility");
  EXPECT_EQ(failures[0].kind, "wrong_primitive") << "4 of the 7 hard pixels";
  EXPECT_EQ(failures[0].message, "7 hard px (missing 1, extra 2, wrong_primitive 4), worst (3,4)");
  EXPECT_EQ(failures[0].fixture_file, "/scenes/b.json");
  EXPECT_EQ(failures[0].run, "runs/00000-00009");
  EXPECT_EQ(failures[0].images, "runs/00000-00009/pairs/b/ref_vs_x");
  EXPECT_EQ(failures[1].cls, "depth");
  EXPECT_EQ(failures[1].kind, "");
  EXPECT_EQ(failures[1].message,
            "12 px over tolerance, max 40.5 steps, worst (1,2): 40.5 steps, allowance 1.235");
  EXPECT_EQ(failures[2].cls, "error");
  EXPECT_EQ(failures[2].reduction, "skipped");
  EXPECT_EQ(failures[2].message, "c: gl:egl:softpipe: crashed (Segmentation fault)");
}

// The campaign re-applies the expectations file to its runs' reports: an entry added
// after a run covers its failures (scoped like `run` scopes it: backend, GL version from
// the row's stacks, render state), the row's own stale `known` no longer counts, and a
// pair is known only when all its failing classes are; entries scoped by tags see the
// fixture's tags.
TEST(CampaignFailures, ExpectationsAreAppliedAsTheyAreNowNotAsTheRunMarkedThem) {
  const Expectations x = parseExpectations(json::parse(R"({"expectations": [
      {"id": "sp-d16-depth", "fixture": "*", "backend": "gl:*:softpipe", "driver_version": "*Mesa 22.*",
       "state": {"depth_format": "d16"}, "class": "depth", "reason": "r"},
      {"id": "sp-d16-vis", "fixture": "*", "backend": "gl:*:softpipe", "state": {"depth_format": "d16"},
       "class": "visibility", "reason": "r"},
      {"id": "sp-tagged", "fixture": "*", "backend": "gl:*:softpipe", "tags": ["tag:f"],
       "class": "shading", "reason": "r"}]})"),
                                           "test");
  auto pair = [](const std::string& fixture, const std::string& version, const std::string& depth,
                 const std::string& vis, const std::string& shading) {
    json r = row(fixture, "gl:egl:softpipe", "fail", vis, "fail", shading);
    r["state"] = {{"depth_format", depth}};
    r["stacks"] = {{"actual", {{"gl_version", version}}}, {"expected", nullptr}};
    r["known"] = json::array({{{"id", "stale"}, {"class", "depth"}, {"reason", "old"}}});
    return r;
  };
  const json r = report({pair("a", "3.3 (Core Profile) Mesa 22.3.6", "d16", "pass", "pass"),
                         pair("b", "3.3 (Core Profile) Mesa 22.3.6", "d16", "fail", "pass"),
                         pair("c", "3.3 (Core Profile) Mesa 23.1.0", "d16", "pass", "pass"),
                         pair("d", "3.3 (Core Profile) Mesa 22.3.6", "d24", "pass", "pass"),
                         pair("e", "3.3 (Core Profile) Mesa 22.3.6", "d16", "pass", "fail"),
                         pair("f", "3.3 (Core Profile) Mesa 22.3.6", "d16", "pass", "fail")});
  const auto now = failuresOfReport(r, "runs/0", info, "report.json", &x);
  std::map<std::string, std::string> known;
  for (const CampaignFailure& f : now) known[f.fixture + "/" + f.cls] = f.known;
  EXPECT_EQ(known["a/depth"], "sp-d16-depth");
  EXPECT_EQ(known["b/depth"], "sp-d16-depth");
  EXPECT_EQ(known["b/visibility"], "sp-d16-vis");
  EXPECT_EQ(known["c/depth"], "") << "another Mesa version";
  EXPECT_EQ(known["d/depth"], "") << "another depth format";
  EXPECT_EQ(known["e/depth"], "") << "its shading failure is not covered: not known at all";
  EXPECT_EQ(known["e/shading"], "");
  EXPECT_EQ(known["f/shading"], "sp-tagged") << "scoped by the fixture's tags";
  // Without the file, what the run wrote.
  for (const CampaignFailure& f : read(r))
    if (f.cls == "depth") {
      EXPECT_EQ(f.known, "stale") << f.fixture;
    }
}

TEST(CampaignFailures, MalformedReportsNameTheFileAndPath) {
  try {
    read(json{{"results", {{{"status", "fail"}}}}});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "report.json: results[0].fixture: missing");
  }
  EXPECT_THROW(read(json::object()), InputError);
}

TEST(CampaignFailures, RecordsRoundTripAndBadOnesAreRefused) {
  CampaignFailure f = read(report({row("b", "gl:egl:softpipe", "fail", "pass", "fail")}))[0];
  f.reduction = "reduced";
  f.reduced_file = "failures/x/reduced.json";
  f.triangles = 3;
  f.reproduces = true;
  f.involved = {"depth_format=d16"};
  f.probe_notes = {"visibility zbuffer -> painter: not compared: crashed"};
  const CampaignFailure back = campaignFailureFromJson(toJson(f), "failure.json");
  EXPECT_EQ(toJson(back), toJson(f));
  json bad = toJson(f);
  bad["class"] = "colour";
  EXPECT_THROW(campaignFailureFromJson(bad, "failure.json"), InputError);
  bad = toJson(f);
  bad["reproduces"] = "yes";
  EXPECT_THROW(campaignFailureFromJson(bad, "failure.json"), InputError);
}

CampaignFailure failure(const std::string& fixture, const std::string& actual,
                        const std::string& cls, std::vector<std::string> involved,
                        std::uint64_t triangles = 5, std::optional<bool> reproduces = true) {
  CampaignFailure f;
  f.id = fixture + "__" + cls;
  f.fixture = fixture;
  f.expected = "ref";
  f.actual = actual;
  f.cls = cls;
  f.involved = std::move(involved);
  f.triangles = triangles;
  f.reproduces = reproduces;
  f.reduction = "reduced";
  f.reduced_file = "failures/" + f.id + "/reduced.json";
  f.tags = {"random", "depth_format:d16", "tag:" + fixture};
  return f;
}

TEST(CampaignSignatures, BackendClassAndWhatTheFailureNeeds) {
  CampaignFailure f = failure("a", "gl:egl:softpipe", "depth", {"depth_format=d16"});
  EXPECT_EQ(signatureOf(f), "gl:egl:softpipe | depth | depth_format=d16");
  f.expected = "gl:egl:llvmpipe";
  EXPECT_EQ(signatureOf(f), "gl:egl:softpipe vs gl:egl:llvmpipe | depth | depth_format=d16");
  f = failure("a", "gl:egl:llvmpipe", "visibility", {});
  f.kind = "missing";
  EXPECT_EQ(signatureOf(f),
            "gl:egl:llvmpipe | visibility:missing | independent of the probed state");
  f.reproduces = false;
  EXPECT_EQ(signatureOf(f),
            "gl:egl:llvmpipe | visibility:missing | not reproduced by its reduced fixture");
  f.cls = "error";
  f.kind = "";
  f.message = "random/s1/00003: gl:egl:zink: crashed (Aborted)";
  f.fixture = "random/s1/00003";
  EXPECT_EQ(signatureOf(f), "gl:egl:llvmpipe | error | FIXTURE: gl:egl:zink: crashed (Aborted)");
}

TEST(CampaignGroups, SameSignatureSameGroupLargestFirst) {
  const std::vector<CampaignFailure> failures = {
      failure("a", "gl:egl:softpipe", "depth", {"depth_format=d16"}, 40),
      failure("b", "gl:egl:llvmpipe", "shading", {"texture"}),
      failure("c", "gl:egl:softpipe", "depth", {"depth_format=d16"}, 2, false),
      failure("d", "gl:egl:softpipe", "depth", {"depth_format=d16"}, 9),
  };
  const std::vector<CampaignGroup> groups = groupFailures(failures);
  ASSERT_EQ(groups.size(), 3u);
  const CampaignGroup& g = groups[0];
  EXPECT_EQ(g.signature, "gl:egl:softpipe | depth | depth_format=d16");
  ASSERT_EQ(g.failures.size(), 2u) << "c does not reproduce: its own signature";
  EXPECT_EQ(g.failures[0]->fixture, "a");
  EXPECT_EQ(g.failures[1]->fixture, "d");
  ASSERT_NE(g.reproducer, nullptr);
  EXPECT_EQ(g.reproducer->fixture, "d") << "the smallest that fails again";
  EXPECT_EQ(g.common_tags, std::vector<std::string>{"depth_format:d16"});
  EXPECT_EQ(g.involved, std::vector<std::string>{"depth_format=d16"});
  EXPECT_EQ(g.id.size(), 8u);
  EXPECT_EQ(groupFailures(failures)[0].id, g.id) << "ids depend on the signature alone";
  EXPECT_EQ(groupFailures({failures[3]})[0].id, g.id);
  EXPECT_NE(groups[1].id, g.id);
  EXPECT_EQ(groups[1].signature, "gl:egl:llvmpipe | shading | texture");
  EXPECT_EQ(groups[2].signature, "gl:egl:softpipe | depth | not reproduced by its reduced fixture");
}

TEST(CampaignGroups, AReproducerThatFailsBeatsASmallerOneThatDoesNot) {
  std::vector<CampaignFailure> failures = {
      failure("a", "gl", "shading", {}, 50, true),
      failure("b", "gl", "shading", {}, 1, std::nullopt),
  };
  EXPECT_EQ(groupFailures(failures)[0].reproducer->fixture, "a");
  failures[0].reduced_file.clear();
  EXPECT_EQ(groupFailures(failures)[0].reproducer->fixture, "b");
  failures[1].reduced_file.clear();
  EXPECT_EQ(groupFailures(failures)[0].reproducer, nullptr);
}

TEST(CampaignSummary, CommandQuotingAndExitCodes) {
  EXPECT_EQ(shellQuote("gl:egl:llvmpipe"), "gl:egl:llvmpipe");
  EXPECT_EQ(shellQuote("a b'c"), "'a b'\\''c'");
  EXPECT_EQ(reproduceCommand("/x y/r.json", "ref", "gl:egl:softpipe", {"depth.fail=8"}, "/tmp/o"),
            "rastercheck run '/x y/r.json' --backends gl:egl:softpipe --against ref -t "
            "depth.fail=8 --out /tmp/o");

  CampaignSummary s;
  s.backends["gl:egl:llvmpipe"] = {10, 0, 0, 0};
  EXPECT_EQ(campaignExitCode(s, {}), kExitPass);
  s.failures = {failure("a", "gl:egl:llvmpipe", "depth", {})};
  const auto groups = groupFailures(s.failures);
  EXPECT_EQ(campaignExitCode(s, groups), kExitFail) << "expectations not checked";
  s.group_files[groups[0].id].expectation = {true, ""};
  EXPECT_EQ(campaignExitCode(s, groups), kExitFail) << "checked, none covers it";
  s.group_files[groups[0].id].expectation = {true, "softpipe d16 depth"};
  EXPECT_EQ(campaignExitCode(s, groups), kExitPass);
  s.backends["gl:egl:zink"] = {0, 0, 0, 1};
  EXPECT_EQ(campaignExitCode(s, groups), kExitBackend);
}

TEST(CampaignSummary, FilesNameEveryGroupItsReproducerAndCommand) {
  CampaignSummary s;
  s.options = {{"seed", 7}, {"profile", "all"}, {"max_size", "64x48"}};
  s.command = "rastercheck campaign --seed 7";
  s.scenes_total = 10;
  s.scenes_run = 4;
  s.backends["gl:egl:softpipe"] = {3, 0, 1, 0};
  s.failures = {failure("a", "gl:egl:softpipe", "depth", {"depth_format=d16"})};
  s.failures_done = 1;
  s.runs = {"runs/00000-00003"};
  const auto groups = groupFailures(s.failures);
  s.group_files[groups[0].id] = {
      "groups/" + groups[0].id + "/reproducer.json", "rastercheck run X", {}};
  const std::string md = summaryMarkdown(s, groups);
  EXPECT_THAT(md, HasSubstr("4 of 10 scenes run (seed 7"));
  EXPECT_THAT(md, HasSubstr("**Incomplete**"));
  EXPECT_THAT(md, HasSubstr("| `gl:egl:softpipe` | 4 | 3 | 0 | 1 | 0 |"));
  EXPECT_THAT(md, HasSubstr("| depth | depth_format=d16 | 1 |"));
  EXPECT_THAT(md, HasSubstr("- reproduce: `rastercheck run X`"));
  EXPECT_THAT(md, HasSubstr("not checked"));
  const json j = summaryJson(s, groups);
  EXPECT_EQ(j["format"], kCampaignFormat);
  EXPECT_EQ(j["complete"], false);
  EXPECT_EQ(j["groups"][0]["count"], 1);
  EXPECT_EQ(j["groups"][0]["reproducer_fails"], true);
  EXPECT_EQ(j["groups"][0]["expectation"]["checked"], false);
  EXPECT_EQ(j["failures"][0]["signature"], groups[0].signature);
  EXPECT_EQ(j["exit_code"], kExitFail);
  EXPECT_THAT(indexHtml(s, groups), HasSubstr("runs/00000-00003/report.html"));
}

TEST(CampaignEta, ScenesAtTheirRateThenFailures) {
  CampaignProgress p;
  p.scenes_left = 100;
  EXPECT_FALSE(secondsLeft(p)) << "nothing measured yet";
  p.scenes_done = 10;
  p.scene_seconds = 20.0;  // 2 s per scene
  p.scenes_done_total = 50;
  p.failures_found = 5;  // 1 in 10 scenes: 10 more expected
  p.failures_left = 5;
  p.reduce_cap_seconds = 60.0;
  p.parallel = 2;  // unmeasured: 15 s per failure
  EXPECT_DOUBLE_EQ(*secondsLeft(p), 200.0 + 15 * 15.0);
  p.failures_done = 4;
  p.failure_seconds = 20.0;  // measured: 5 s per failure
  EXPECT_DOUBLE_EQ(*secondsLeft(p), 200.0 + 15 * 5.0);
}

}  // namespace
}  // namespace rc
