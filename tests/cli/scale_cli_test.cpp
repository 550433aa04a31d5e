// The commands for many fixtures and many machines, as a user runs them: `run --shard K/N`
// parts merged by `merge` give what one unsharded run gives (report.json rows, junit.xml,
// report.html, pair images, the accuracy report), `--shard env` reads GitLab CI's and a
// Kubernetes Indexed Job's variables, merge refuses incomplete or foreign parts, and
// `diff-runs` sorts pairs into regressions, fixes, new and vanished. Also the launcher's
// --version without the heavy libraries. Reference backends only: no GL needed.

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/command.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Result = rc::test::CommandResult;

Result run(const std::string& args, const std::string& env = "") {
  return rc::test::runShell(env + " " RC_EXE " " + args);
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_scale_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string catalog(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/fixtures/scenes/" + rel;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Small fixtures where painter's order fails on some (failing pairs have images).
const std::string kFixtures = catalog("coverage") + " " + catalog("zbuffer") + " " +
                              catalog("visibility") + " " + catalog("culling");
const std::string kBackends = " --backends ref:painter,ref:subpixel=4 ";

// report.json without what differs between two runs of the same pairs: time taken,
// the shard record and the command line.
json withoutTimings(json j) {
  j.erase("shard");
  for (json& row : j["results"]) {
    row.erase("seconds");
    row.erase("render_seconds");
  }
  return j;
}

// results.csv without its durations (the third column).
std::string withoutDurations(const std::string& csv) {
  return std::regex_replace(csv, std::regex(",[^,\n]*\n"), "\n");
}

std::string withoutTimes(std::string xml) {
  return std::regex_replace(xml, std::regex("time=\"[0-9.]+\""), "time=\"\"");
}

std::set<std::string> filesUnder(const fs::path& dir) {
  std::set<std::string> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.insert(e.path().lexically_relative(dir).string());
  return out;
}

TEST(CliScale, ShardsMergedAreTheUnshardedRun) {
  const fs::path dir = scratch("merge");
  const Result whole = run("run " + kFixtures + kBackends + "--out " + (dir / "whole").string());
  ASSERT_EQ(whole.code, 1) << whole.out;  // painter's order fails somewhere
  std::string shards;
  std::size_t rows = 0;
  for (int k = 1; k <= 3; ++k) {
    const fs::path part = dir / ("part" + std::to_string(k));
    const Result r = run("run " + kFixtures + kBackends + "--shard " + std::to_string(k) +
                         "/3 --out " + part.string());
    EXPECT_LE(r.code, 1) << r.out;
    const json report = json::parse(readFile(part / "report.json"));
    EXPECT_EQ(report["shard"]["index"], k);
    EXPECT_EQ(report["shard"]["count"], 3);
    EXPECT_GT(report["results"].size(), 0u) << "shard " << k << " got nothing to do";
    rows += report["results"].size();
    shards += " " + part.string();
  }
  const json whole_json = json::parse(readFile(dir / "whole" / "report.json"));
  EXPECT_EQ(rows, whole_json["results"].size()) << "every pair in exactly one shard";

  const Result merged = run("merge" + shards + " --out " + (dir / "merged").string());
  EXPECT_EQ(merged.code, whole.code) << merged.out;
  EXPECT_EQ(withoutTimings(json::parse(readFile(dir / "merged" / "report.json"))),
            withoutTimings(whole_json));
  EXPECT_EQ(withoutTimes(readFile(dir / "merged" / "junit.xml")),
            withoutTimes(readFile(dir / "whole" / "junit.xml")));
  EXPECT_EQ(readFile(dir / "merged" / "report.html"), readFile(dir / "whole" / "report.html"));
  EXPECT_EQ(withoutDurations(readFile(dir / "merged" / "results.csv")),
            withoutDurations(readFile(dir / "whole" / "results.csv")));
  EXPECT_FALSE(readFile(dir / "merged" / "results.csv").empty());
  EXPECT_EQ(filesUnder(dir / "merged" / "pairs"), filesUnder(dir / "whole" / "pairs"));
  EXPECT_FALSE(filesUnder(dir / "merged" / "pairs").empty());
  EXPECT_EQ(filesUnder(dir / "merged" / "frames"), filesUnder(dir / "whole" / "frames"));
  // The accuracy report reads the merged folder as it reads the whole run.
  const Result acc_whole = run("accuracy " + (dir / "whole").string() + " --command x");
  const Result acc_merged = run("accuracy " + (dir / "merged").string() + " --command x");
  EXPECT_EQ(acc_whole.code, 0) << acc_whole.out;
  std::string a = acc_whole.out, b = acc_merged.out;
  const std::string whole_name = (dir / "whole").string(), merged_name = (dir / "merged").string();
  for (std::size_t at; (at = a.find(whole_name)) != std::string::npos;)
    a.replace(at, whole_name.size(), "RUN");
  for (std::size_t at; (at = b.find(merged_name)) != std::string::npos;)
    b.replace(at, merged_name.size(), "RUN");
  EXPECT_EQ(a, b);

  // A missing part, a part twice, or a part of another run: exit 2, nothing written.
  const Result missing = run("merge " + (dir / "part1").string() + " " + (dir / "part3").string() +
                             " --out " + (dir / "bad").string());
  EXPECT_EQ(missing.code, 2) << missing.out;
  EXPECT_NE(missing.out.find("shard 2/3 is missing"), std::string::npos) << missing.out;
  const Result twice =
      run("merge" + shards + " " + (dir / "part2").string() + " --out " + (dir / "bad").string());
  EXPECT_EQ(twice.code, 2) << twice.out;
  const Result other = run("run " + catalog("coverage") + kBackends + "--shard 2/3 --out " +
                           (dir / "other").string());
  const Result foreign = run("merge " + (dir / "part1").string() + " " + (dir / "other").string() +
                             " " + (dir / "part3").string() + " --out " + (dir / "bad").string());
  EXPECT_EQ(foreign.code, 2) << foreign.out;
  EXPECT_NE(foreign.out.find("not a shard of the same run"), std::string::npos) << foreign.out;
  EXPECT_FALSE(fs::exists(dir / "bad"));
  fs::remove_all(dir);
}

TEST(CliScale, ShardEnvReadsGitLabAndKubernetesVariables) {
  const fs::path dir = scratch("env");
  const std::string args = "run " + catalog("coverage") + kBackends + "--shard env --out ";
  Result r = run(args + (dir / "gitlab").string(), "CI_NODE_INDEX=2 CI_NODE_TOTAL=3");
  EXPECT_LE(r.code, 1) << r.out;
  json j = json::parse(readFile(dir / "gitlab" / "report.json"));
  EXPECT_EQ(j["shard"]["index"], 2);
  EXPECT_EQ(j["shard"]["count"], 3);
  r = run(args + (dir / "k8s").string(), "JOB_COMPLETION_INDEX=0 JOB_COMPLETIONS=2");
  EXPECT_LE(r.code, 1) << r.out;
  j = json::parse(readFile(dir / "k8s" / "report.json"));
  EXPECT_EQ(j["shard"]["index"], 1);
  EXPECT_EQ(j["shard"]["count"], 2);
  // Nothing set, or an index out of range: one line, exit 2, nothing written.
  r = run(args + (dir / "none").string(),
          "env -u CI_NODE_INDEX -u CI_NODE_TOTAL -u JOB_COMPLETION_INDEX -u RASTERCHECK_SHARD");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("JOB_COMPLETION_INDEX"), std::string::npos) << r.out;
  r = run(args + (dir / "none").string(), "CI_NODE_INDEX=4 CI_NODE_TOTAL=3");
  EXPECT_EQ(r.code, 2) << r.out;
  r = run("run " + catalog("coverage") + kBackends + "--shard 0/3 --out " +
          (dir / "none").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_FALSE(fs::exists(dir / "none"));
  fs::remove_all(dir);
}

TEST(CliScale, DiffRunsFindsRegressionsFixesNewAndVanished) {
  const fs::path dir = scratch("diff");
  // Strict: painter's order fails on interpenetrating quads. Lenient: every visibility
  // mismatch forgiven, so those pairs pass. Plus one fixture only in each run.
  const std::string lenient = " -t visibility.warn=1000000 -t visibility.fail=1000000 ";
  Result r = run("run " + catalog("zbuffer") + " " + catalog("coverage/triangle_fan.json") +
                 " --backends ref:painter --out " + (dir / "strict").string());
  ASSERT_EQ(r.code, 1) << r.out;
  r = run("run " + catalog("zbuffer") + " " + catalog("culling/cull_back_ccw.json") +
          " --backends ref:painter" + lenient + "--out " + (dir / "lenient").string());
  ASSERT_LE(r.code, 1) << r.out;

  const Result fixes = run("diff-runs " + (dir / "strict").string() + " " +
                           (dir / "lenient").string() + " --out " + (dir / "d").string());
  EXPECT_EQ(fixes.code, 0) << fixes.out;
  EXPECT_NE(fixes.out.find("Fixes:"), std::string::npos) << fixes.out;
  EXPECT_NE(fixes.out.find("zbuffer/interpenetrating_ab ref vs ref:painter: FAIL -> PASS"),
            std::string::npos)
      << fixes.out;
  EXPECT_NE(fixes.out.find("visibility fail -> pass (hard px "), std::string::npos) << fixes.out;
  EXPECT_NE(fixes.out.find("New pairs:"), std::string::npos);
  EXPECT_NE(fixes.out.find("culling/cull_back_ccw"), std::string::npos);
  EXPECT_NE(fixes.out.find("Vanished pairs:"), std::string::npos);
  EXPECT_NE(fixes.out.find("NO REGRESSIONS"), std::string::npos);
  for (const char* f : {"diff.txt", "diff.json", "diff.html"})
    EXPECT_TRUE(fs::is_regular_file(dir / "d" / f)) << f;
  EXPECT_EQ(readFile(dir / "d" / "diff.txt"), fixes.out);

  // The other way round: the same pairs are regressions, and the exit code says so.
  const Result regressions =
      run("diff-runs " + (dir / "lenient").string() + " " + (dir / "strict").string() + " --json");
  EXPECT_EQ(regressions.code, 1) << regressions.out;
  const json j = json::parse(regressions.out);
  EXPECT_GE(j["counts"]["regression"].get<int>(), 1);
  EXPECT_EQ(j["counts"]["fix"], 0);
  EXPECT_EQ(j["counts"]["new"], 1);
  EXPECT_EQ(j["counts"]["vanished"], 1);
  EXPECT_EQ(j["counts"]["regression"], j["classes"]["visibility"]["transitions"]["pass->fail"]);
  bool found = false;
  for (const json& p : j["pairs"]) {
    if (p["fixture"] != "zbuffer/interpenetrating_ab") continue;
    found = true;
    EXPECT_EQ(p["kind"], "regression");
    EXPECT_EQ(p["before"]["status"], "pass");
    EXPECT_EQ(p["after"]["status"], "fail");
    EXPECT_GT(p["after"]["visibility"]["pixels"].get<int>(), 0);
  }
  EXPECT_TRUE(found) << regressions.out;
  // Bad input: one line, exit 2.
  const Result bad = run("diff-runs " + (dir / "strict").string() + " " + (dir / "nope").string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  fs::remove_all(dir);
}

TEST(CliScale, VersionIsAnsweredWithoutLoadingTheHeavyLibraries) {
  const Result r = run("--version", "LD_DEBUG=libs");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("rastercheck 0."), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("OpenImageIO"), std::string::npos) << "--version loaded OpenImageIO";
  EXPECT_EQ(r.out.find("assimp"), std::string::npos);
  // Every other command still reaches the whole program.
  const Result help = run("--help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("diff-runs"), std::string::npos) << help.out;
  EXPECT_EQ(help.out.find("worker"), std::string::npos) << "the worker mode is not for people";
}

// OpenImageIO comes with the image module, loaded when a command touches an image
// (fixtures/image_io.h): `list` of untextured fixtures never does (it loads each scene, so
// a textured one would), `render` writes frame.exr and color.png.
TEST(CliScale, OnlyCommandsThatTouchImagesLoadOpenImageIO) {
  const Result list = run("list " + catalog("zbuffer"), "LD_DEBUG=libs");
  EXPECT_EQ(list.code, 0) << list.out;
  EXPECT_NE(list.out.find("zbuffer/interpenetrating_ab"), std::string::npos) << list.out;
  EXPECT_EQ(list.out.find("libOpenImageIO"), std::string::npos) << "list loaded OpenImageIO";
  EXPECT_EQ(list.out.find("libassimp"), std::string::npos) << "list loaded Assimp";
  const fs::path out = scratch("image_io");
  const std::string render_args =
      "render " + catalog("zbuffer/interpenetrating_ab.json") + " --backend ref --out ";
  // The frame files are encoded here (a private user cache, empty: fixtures/shared_cache.h).
  const std::string cache = "RASTERCHECK_CACHE_DIR=" + (out / "cache").string();
  const Result render = run(render_args + (out / "a").string(), cache + " LD_DEBUG=libs");
  EXPECT_EQ(render.code, 0) << render.out;
  EXPECT_NE(render.out.find("rastercheck-image-io.so"), std::string::npos) << render.out;
  EXPECT_NE(render.out.find("libOpenImageIO"), std::string::npos) << render.out;
  EXPECT_TRUE(fs::is_regular_file(out / "a" / "frame.exr"));
  EXPECT_TRUE(fs::is_regular_file(out / "a" / "color.png"));
  // The same frame again: its files come from the user cache, the same bytes, and nothing
  // loads the image library.
  const Result again = run(render_args + (out / "b").string(), cache + " LD_DEBUG=libs");
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_EQ(again.out.find("libOpenImageIO"), std::string::npos) << "loaded OpenImageIO again";
  for (const char* name : {"frame.exr", "color.png"})
    EXPECT_EQ(readFile(out / "a" / name), readFile(out / "b" / name)) << name;
  fs::remove_all(out);
}

}  // namespace
