// `rastercheck campaign` end to end on real Mesa drivers (labels gl, campaign):
//  - the short campaign (fixed seed, 50 scenes, every campaign backend): every failing
//    class that the runs' own report.json files show is a failure of the summary, grouped,
//    reduced, with a reproducer whose command still fails in that class; running the same
//    command again does no work;
//  - injected faults (RASTERCHECK_GL_FAULT) form groups with the right signature, whose
//    reproducers fail with the fault and pass without it;
//  - Ctrl-C keeps finished work and the same command continues;
//  - the short mutation study: every fault that changes a pixel beyond its allowance is
//    caught in its class.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/command.h"

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

namespace {

// The backends of the campaign: every Mesa driver the project's machines have (zink is
// GL on Vulkan over lavapipe, installed by scripts/setup.sh).
const char* const kBackends = "gl:egl:llvmpipe,gl:egl:softpipe,gl:egl:zink";

fs::path scratch(const std::string& name) {
  fs::path p =
      fs::temp_directory_path() / ("rc_campaign_gl_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

json readJson(const fs::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

rc::test::CommandResult campaign(const std::string& args, const std::string& env = "") {
  return rc::test::runShell(env + " " RC_EXE " campaign " + args, /*separate_err=*/true);
}

// The summary's command with our binary for `rastercheck`.
rc::test::CommandResult reproduce(const std::string& command, const std::string& env = "") {
  EXPECT_EQ(command.rfind("rastercheck ", 0), 0u) << command;
  return rc::test::runShell(env + " " RC_EXE + command.substr(std::string("rastercheck").size()));
}

// The failing classes of the only row of a run's report.json.
std::set<std::string> failingClasses(const fs::path& run_dir) {
  const json report = readJson(run_dir / "report.json");
  std::set<std::string> out;
  for (const char* cls : {"visibility", "depth", "shading"})
    if (report["results"][0][cls]["status"] == "fail") out.insert(cls);
  return out;
}

// The folder or a file in it changed since `t` (nothing in it may have been rewritten).
fs::file_time_type newest(const fs::path& dir) {
  fs::file_time_type t = fs::last_write_time(dir);
  for (const auto& e : fs::recursive_directory_iterator(dir))
    t = std::max(t, fs::last_write_time(e.path()));
  return t;
}

bool glRequired() {
  const char* env = std::getenv("RASTERCHECK_REQUIRE_GL");
  return env != nullptr && std::string(env) == "1";
}

// Skips (or, under RASTERCHECK_REQUIRE_GL=1, fails) when llvmpipe cannot start here.
#define REQUIRE_GL()                                                                        \
  do {                                                                                      \
    const fs::path probe = scratch("probe");                                                \
    const auto r = rc::test::runShell(RC_EXE " render " RC_SOURCE_DIR                       \
                                             "/fixtures/scenes/coverage/triangle_fan.json " \
                                             "--backend gl:egl:llvmpipe --out " +           \
                                      probe.string());                                      \
    fs::remove_all(probe);                                                                  \
    if (r.code != 0) {                                                                      \
      if (glRequired()) FAIL() << "gl:egl:llvmpipe cannot start: " << r.out;                \
      GTEST_SKIP() << "gl:egl:llvmpipe cannot start: " << r.out;                            \
    }                                                                                       \
  } while (0)

TEST(CampaignGl, ShortCampaignFindsGroupsAndReproducesEveryOne) {
  REQUIRE_GL();
  const fs::path dir = scratch("short");
  const std::string args = std::string("--seed 11 --count 50 --backends ") + kBackends +
                           " --max-size 48x36 --reduce-seconds 6 --jobs 2 --out " + dir.string();
  const rc::test::CommandResult first = campaign(args);
  // The target of the campaign issue, in small: no failure on llvmpipe or zink, and on
  // softpipe only groups an expectations entry covers (exit 0). A group that is not
  // covered is a false alarm of the harness or a new driver difference: either way a bug
  // to pin down (summary.md names it and its reproducer).
  ASSERT_EQ(first.code, 0) << first.out << first.err;
  EXPECT_THAT(first.err, HasSubstr("starting a campaign in"));
  EXPECT_EQ(first.err.find('\r'), std::string::npos) << "no status line when not a terminal";
  EXPECT_THAT(first.out, HasSubstr("summary: " + (dir / "summary.md").string()));
  const json summary = readJson(dir / "summary.json");
  EXPECT_EQ(summary["complete"], true);
  EXPECT_EQ(summary["scenes"]["run"], 50);
  for (const char* b : {"gl:egl:llvmpipe", "gl:egl:softpipe", "gl:egl:zink"})
    EXPECT_EQ(summary["backends"][b]["pairs"], 50) << b;
  // No unexplained failure on llvmpipe or zink: each of their groups is a Mesa difference an
  // expectations entry names (seed 11 meets mesa-polygon-mode-stencil-front: a back-facing
  // polygon in polygon mode point tested with the front stencil state).
  for (const json& g : summary["groups"]) {
    const std::string actual = g["actual"].get<std::string>();
    if (actual == "gl:egl:llvmpipe" || actual == "gl:egl:zink") {
      EXPECT_TRUE(g["expectation"]["entry"].is_string()) << g.dump();
    }
  }
  EXPECT_EQ(summary["exit_code"], first.code);

  // The runs' own reports, read independently: every failing class is one failure.
  std::set<std::string> from_reports;
  int runs = 0;
  for (const auto& e : fs::directory_iterator(dir / "runs")) {
    ASSERT_TRUE(std::regex_match(e.path().filename().string(), std::regex("[0-9]{5}-[0-9]{5}")))
        << "a half-written run is left: " << e.path();
    ++runs;
    EXPECT_FALSE(fs::exists(e.path() / "frames")) << "frames are not kept";
    const json report = readJson(e.path() / "report.json");
    for (const json& row : report["results"])
      for (const char* cls : {"visibility", "depth", "shading"})
        if (row["status"] == "fail" && row[cls]["status"] == "fail")
          from_reports.insert(row["fixture"].get<std::string>() + " " +
                              row["actual"].get<std::string>() + " " + cls);
  }
  EXPECT_EQ(runs, 3) << "50 scenes in runs of 20";
  std::set<std::string> from_summary;
  std::map<std::string, std::string> group_of;
  for (const json& f : summary["failures"]) {
    from_summary.insert(f["fixture"].get<std::string>() + " " + f["actual"].get<std::string>() +
                        " " + f["class"].get<std::string>());
    EXPECT_THAT(std::string(f["reduction"]), ::testing::AnyOf("reduced", "timed_out", "failed"))
        << f.dump();
  }
  EXPECT_EQ(from_summary, from_reports);

  // Every failure in exactly one group; every group's reproducer fails again in its class.
  std::size_t grouped = 0;
  for (const json& g : summary["groups"]) {
    grouped += g["count"].get<std::size_t>();
    ASSERT_FALSE(g["reproducer"].is_null()) << g.dump();
    EXPECT_EQ(g["reproducer_fails"], true) << g.dump();
    EXPECT_TRUE(fs::exists(dir / g["reproducer"].get<std::string>()));
    EXPECT_EQ(g["expectation"]["checked"], true) << g.dump();
  }
  EXPECT_EQ(grouped, summary["failures"].size());
  int reproduced = 0;
  for (const json& g : summary["groups"]) {
    if (reproduced == 3) break;  // enough to show the commands work, and keeps the test short
    const std::string command = g["command"];
    const fs::path out = command.substr(command.rfind(' ') + 1);
    const rc::test::CommandResult r = reproduce(command);
    // A group an expectations entry covers reproduces as a known failure (run exits 0).
    const bool known = g["expectation"]["entry"].is_string();
    EXPECT_EQ(r.code, known ? 0 : 1) << command << "\n" << r.out;
    if (known) {
      EXPECT_NE(r.out.find("KNOWN FAIL"), std::string::npos) << r.out;
    }
    EXPECT_TRUE(failingClasses(out).contains(g["class"].get<std::string>())) << command;
    fs::remove_all(out);
    ++reproduced;
  }

  // The same command again: nothing is run, reduced or rewritten but the summary.
  const auto before = newest(dir / "runs");
  const auto failures_before = fs::exists(dir / "failures") ? newest(dir / "failures") : before;
  const rc::test::CommandResult again = campaign(args);
  EXPECT_EQ(again.code, first.code) << again.err;
  EXPECT_THAT(again.err, HasSubstr("continuing the campaign in " + dir.string() +
                                   ": 50 of 50 scenes already run"));
  EXPECT_EQ(newest(dir / "runs"), before);
  if (fs::exists(dir / "failures")) {
    EXPECT_EQ(newest(dir / "failures"), failures_before);
  }
  EXPECT_EQ(readJson(dir / "summary.json")["groups"], summary["groups"]);
  EXPECT_FALSE(fs::exists(dir / ".work"));
  fs::remove_all(dir);
}

TEST(CampaignGl, InjectedFaultsFormGroupsWithTheirSignatureAndReproducers) {
  REQUIRE_GL();
  const fs::path dir = scratch("faults");
  const std::string fault = "RASTERCHECK_GL_FAULT=light_scale=1.5,drop_primitive=1";
  const rc::test::CommandResult r = campaign(
      "--seed 2 --count 2 --profile generators --max-size 48x36 --backends "
      "gl:egl:llvmpipe --reduce-seconds 10 --jobs 2 --out " +
          dir.string(),
      fault);
  ASSERT_EQ(r.code, 1) << r.out << r.err;
  const json summary = readJson(dir / "summary.json");
  const json* shading = nullptr;
  const json* missing = nullptr;
  for (const json& g : summary["groups"]) {
    EXPECT_EQ(g["actual"], "gl:egl:llvmpipe");
    if (g["class"] == "shading") shading = &g;
    if (g["class"] == "visibility" && g["kind"] == "missing") missing = &g;
  }
  ASSERT_NE(shading, nullptr) << "every light 50 % brighter must fail in shading: " << r.out;
  ASSERT_NE(missing, nullptr) << "a dropped triangle must be missing: " << r.out;
  EXPECT_THAT((*shading)["involved"].get<std::vector<std::string>>(), ::testing::Contains("lights"))
      << "without lights the brighter lights change nothing: " << shading->dump();
  for (const json* g : {shading, missing}) {
    const std::string cls = (*g)["class"];
    const std::string command = (*g)["command"];
    const fs::path out = command.substr(command.rfind(' ') + 1);
    const rc::test::CommandResult with = reproduce(command, fault);
    EXPECT_EQ(with.code, 1) << command << "\n" << with.out;
    EXPECT_TRUE(failingClasses(out).contains(cls)) << command;
    const rc::test::CommandResult without = reproduce(command);
    EXPECT_FALSE(failingClasses(out).contains(cls))
        << "the reproducer fails without the fault: the group is not the fault's\n"
        << without.out;
    fs::remove_all(out);
  }
  fs::remove_all(dir);
}

TEST(CampaignGl, ProgressIsRedrawnInPlaceOnATerminal) {
  REQUIRE_GL();
  const fs::path dir = scratch("tty");
  const fs::path typescript = scratch("tty_typescript");
  // `script` runs the command on a pseudo-terminal and records what it wrote there.
  const rc::test::CommandResult r =
      rc::test::runShell("script -qfec '" RC_EXE
                         " campaign --seed 4 --count 2 --batch 1 --max-size 32x24 "
                         "--backends gl:egl:llvmpipe --reduce-seconds 0 --out " +
                         dir.string() + "' " + typescript.string());
  EXPECT_TRUE(r.code == 0 || r.code == 1) << r.out;
  const std::string text = readText(typescript);
  EXPECT_THAT(text, HasSubstr("\rcampaign: scenes 0/2 (0 %), 0 failures; running 0..0"));
  EXPECT_THAT(text, HasSubstr("\rcampaign: scenes 1/2 (50 %)"));
  EXPECT_THAT(text, HasSubstr("; ETA ")) << text;
  fs::remove_all(dir);
  fs::remove(typescript);
}

// Starts the campaign in the background (its own output files), for signals.
pid_t start(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<std::string> argv = {RC_EXE, "campaign"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> c;
  for (std::string& a : argv) c.push_back(a.data());
  c.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  EXPECT_EQ(posix_spawn(&pid, c[0], &actions, nullptr, c.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

TEST(CampaignGl, CtrlCKeepsFinishedWorkAndTheSameCommandContinues) {
  REQUIRE_GL();
  const fs::path dir = scratch("interrupt");
  const fs::path log = scratch("interrupt_log");
  const std::vector<std::string> args = {"--seed",
                                         "3",
                                         "--count",
                                         "6",
                                         "--batch",
                                         "1",
                                         "--max-size",
                                         "32x24",
                                         "--backends",
                                         "gl:egl:llvmpipe",
                                         "--reduce-seconds",
                                         "5",
                                         "--out",
                                         dir.string()};
  const pid_t pid = start(args, log);
  ASSERT_GT(pid, 0);
  // Interrupt once the first run is in place.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
  while (!fs::exists(dir / "runs" / "00000-00000" / "report.json") &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_TRUE(fs::exists(dir / "runs" / "00000-00000" / "report.json"));
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  const std::string text = readText(log);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT)
      << "an interrupted campaign ends by the signal, as a shell expects\n"
      << text;
  EXPECT_THAT(text, HasSubstr("run the same command again to continue"));
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(name.find(".partial"), std::string::npos) << e.path();
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << e.path();
    EXPECT_NE(name, ".work") << e.path();
  }
  const json partial = readJson(dir / "summary.json");
  EXPECT_EQ(partial["complete"], false);
  const int kept = partial["scenes"]["run"];
  EXPECT_GE(kept, 1);
  EXPECT_LT(kept, 6);
  const auto first_run = fs::last_write_time(dir / "runs" / "00000-00000" / "report.json");

  std::string command = RC_EXE " campaign";
  for (const std::string& a : args) command += " " + a;
  const rc::test::CommandResult again = rc::test::runShell(command, /*separate_err=*/true);
  EXPECT_TRUE(again.code == 0 || again.code == 1) << again.err;
  EXPECT_THAT(again.err, HasSubstr("continuing the campaign in " + dir.string() + ": " +
                                   std::to_string(kept) + " of 6 scenes already run"));
  const json done = readJson(dir / "summary.json");
  EXPECT_EQ(done["complete"], true);
  EXPECT_EQ(done["scenes"]["run"], 6);
  EXPECT_EQ(fs::last_write_time(dir / "runs" / "00000-00000" / "report.json"), first_run)
      << "finished work is kept as it was";
  fs::remove_all(dir);
  fs::remove(log);
}

TEST(CampaignGl, ShortMutationStudyCatchesEveryFaultInItsClass) {
  REQUIRE_GL();
  const fs::path dir = scratch("mutations");
  const rc::test::CommandResult r = campaign(
      "--mutations --seed 5 --count 8 --max-size 64x48 --backends gl:egl:llvmpipe --jobs 2 "
      "--out " +
      dir.string());
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  const json study = readJson(dir / "mutations.json");
  EXPECT_EQ(study["complete"], true);
  const json& faults = study["backends"]["gl:egl:llvmpipe"];
  for (const char* name : {"light_scale", "depth_bias", "drop_primitive", "move_vertex",
                           "texel_offset", "blend_factor"}) {
    ASSERT_TRUE(faults.contains(name)) << name;
    const json& f = faults[name];
    EXPECT_EQ(f["scenes"], 8) << name;
    // The seed is chosen so that every fault changes at least one scene beyond its
    // allowance: a study where nothing counts would prove nothing.
    EXPECT_GE(f["counted"].get<int>(), 1) << name << ": " << f.dump();
    EXPECT_EQ(f["verdicts"]["missed"], 0) << name << ": " << f.dump();
    EXPECT_EQ(f["verdicts"]["error"], 0) << name << ": " << f.dump();
  }
  // The verdicts, checked against the definition from the three comparisons' classes.
  const std::map<std::string, std::string> cls = {
      {"light_scale", "shading"},       {"depth_bias", "depth"},
      {"drop_primitive", "visibility"}, {"move_vertex", "visibility"},
      {"texel_offset", "shading"},      {"blend_factor", "shading"},
      {"depth_func", "visibility"},     {"stencil_op", "depth"},
      {"blend_function", "shading"},    {"scissor_shift", "visibility"},
      {"lod_shift", "shading"},         {"lod_weight", "shading"},
      {"move_line_end", "visibility"},  {"move_point", "visibility"},
      {"shadow_shift", "shading"},      {"shadow_compare", "shading"},
      {"shadow_bias", "shading"}};
  for (const json& result : study["results"]) {
    const std::string c = cls.at(result["fault"]);
    const auto has = [&](const char* key) {
      const auto v = result[key].get<std::vector<std::string>>();
      return std::find(v.begin(), v.end(), c) != v.end();
    };
    if (result["verdict"] == "caught") {
      EXPECT_TRUE(has("effect_fails") && has("detected_fails") && !has("control_fails"))
          << result.dump();
    }
    if (result["verdict"] == "no_effect") {
      EXPECT_FALSE(has("effect_fails")) << result.dump();
    }
  }
  fs::remove_all(dir);
}

}  // namespace
