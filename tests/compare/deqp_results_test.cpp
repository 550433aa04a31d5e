// deqp-runner's files (compare/deqp_results.h): test names, the status vocabulary, the
// baseline rule table as deqp-runner's runner_results.rs applies it, the baseline, flakes
// and skips file formats (with file:line errors), results.csv and failures.csv.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "compare/deqp_results.h"
#include "compare/report.h"
#include "fixtures/errors.h"

namespace rc {
namespace {
namespace fs = std::filesystem;

PairResult row(const std::string& fixture, Status status, const std::string& actual = "gl:x") {
  PairResult r;
  r.fixture = fixture;
  r.expected = "ref";
  r.actual = actual;
  r.status = status;
  r.visibility.status = r.depth.status = r.shading.status =
      status == Status::Fail ? Status::Fail : Status::Pass;
  return r;
}

fs::path writeFile(const std::string& name, const std::string& text) {
  const fs::path p =
      fs::temp_directory_path() / ("rc_deqp_" + name + "_" + std::to_string(::getpid()));
  std::ofstream(p) << text;
  return p;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(DeqpResults, TestNamesAndStatuses) {
  PairResult r = row("shading/sphere", Status::Pass, "gl:egl:llvmpipe");
  EXPECT_EQ(testName(r), "shading/sphere@gl:egl:llvmpipe");
  r.expected = "gl:egl:softpipe";
  EXPECT_EQ(testName(r), "shading/sphere@gl:egl:llvmpipe@gl:egl:softpipe");
  EXPECT_EQ(testName(row("a,b\nc", Status::Pass)), "a_b_c@gl:x") << "one CSV field";

  EXPECT_EQ(runnerStatus(row("a", Status::Pass)), "Pass");
  EXPECT_EQ(runnerStatus(row("a", Status::Warn)), "Warn");
  EXPECT_EQ(runnerStatus(row("a", Status::Fail)), "Fail");
  PairResult known = row("a", Status::Fail);
  known.known.push_back({"id", "depth", "why"});
  EXPECT_EQ(runnerStatus(known), "ExpectedFail");
  PairResult crash = row("a", Status::Error);
  crash.error = "crashed (Segmentation fault)";
  EXPECT_EQ(runnerStatus(crash), "Crash");
  crash.error = "timed out after 5 s (the --timeout watchdog killed its worker)";
  EXPECT_EQ(runnerStatus(crash), "Timeout");
  EXPECT_EQ(runnerStatus(row("a", Status::NotSupported)), "Skip");
  EXPECT_EQ(runnerStatus(row("a", Status::Flake)), "Flake");

  for (const char* ok : {"Pass", "Warn", "Skip", "Flake", "KnownFlake", "ExpectedFail"})
    EXPECT_TRUE(runnerSuccess(ok)) << ok;
  for (const char* bad :
       {"Fail", "Crash", "Timeout", "Missing", "UnexpectedPass", "UnexpectedImprovement(Fail)"})
    EXPECT_FALSE(runnerSuccess(bad)) << bad;
}

// deqp-runner's with_baseline, row by row.
TEST(DeqpResults, BaselineRuleTable) {
  EXPECT_EQ(withBaseline("Fail", "Fail"), "ExpectedFail");
  EXPECT_EQ(withBaseline("Fail", "ExpectedFail"), "ExpectedFail");
  EXPECT_EQ(withBaseline("Fail", "Crash"), "UnexpectedImprovement(Fail)");
  EXPECT_EQ(withBaseline("Fail", "Timeout"), "UnexpectedImprovement(Fail)");
  EXPECT_EQ(withBaseline("Fail", ""), "Fail");
  EXPECT_EQ(withBaseline("Fail", "Flake"), "Fail") << "a baseline Flake changes nothing";
  EXPECT_EQ(withBaseline("Pass", "Fail"), "UnexpectedPass");
  EXPECT_EQ(withBaseline("Pass", "Crash"), "UnexpectedPass");
  EXPECT_EQ(withBaseline("Pass", "Missing"), "UnexpectedPass");
  EXPECT_EQ(withBaseline("Pass", "Pass"), "Pass");
  EXPECT_EQ(withBaseline("Pass", "Flake"), "Pass");
  EXPECT_EQ(withBaseline("Crash", "Crash"), "ExpectedFail");
  EXPECT_EQ(withBaseline("Crash", "ExpectedFail"), "ExpectedFail");
  EXPECT_EQ(withBaseline("Crash", "Fail"), "Crash");
  EXPECT_EQ(withBaseline("Warn", "Warn"), "ExpectedFail");
  EXPECT_EQ(withBaseline("Warn", "Fail"), "UnexpectedImprovement(Warn)");
  EXPECT_EQ(withBaseline("Timeout", "Timeout"), "ExpectedFail");
  EXPECT_EQ(withBaseline("Timeout", "Crash"), "Timeout");
  EXPECT_EQ(withBaseline("Skip", "Fail"), "UnexpectedImprovement(Skip)");
  EXPECT_EQ(withBaseline("ExpectedFail", ""), "ExpectedFail");
  EXPECT_EQ(withBaseline("Flake", "Fail"), "Flake");
}

TEST(DeqpResults, BaselineFileFormat) {
  const fs::path ok = writeFile("ok",
                                "# Mesa-style fails.txt\n\n"
                                "a@gl:x,Fail\n"
                                "b@gl:x,Crash\r\n"
                                "c@gl:x,Pass,0.25\n"
                                "d@gl:x,UnexpectedImprovement(Pass)\n");
  const RunnerBaseline b = readRunnerBaseline(ok);
  ASSERT_EQ(b.expected.size(), 4u);
  EXPECT_EQ(b.expected.at("a@gl:x"), "Fail");
  EXPECT_EQ(b.expected.at("b@gl:x"), "Crash");
  EXPECT_EQ(b.expected.at("c@gl:x"), "Pass") << "a results.csv line: the duration is ignored";

  const fs::path twice = writeFile("twice", "a@gl:x,Fail\na@gl:x,Crash\n");
  EXPECT_EQ(errorOf([&] { readRunnerBaseline(twice); }),
            twice.string() + ":2: a@gl:x is listed twice");
  const fs::path unknown = writeFile("unknown", "a@gl:x,Failed\n");
  EXPECT_NE(errorOf([&] { readRunnerBaseline(unknown); }).find(":1: unknown status \"Failed\""),
            std::string::npos);
  const fs::path bare = writeFile("bare", "a@gl:x\n");
  EXPECT_NE(errorOf([&] { readRunnerBaseline(bare); }).find(":1: \"a@gl:x\": expected NAME,Status"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { readRunnerBaseline("/nonexistent/fails.txt"); }).find("cannot read"),
            std::string::npos);
}

TEST(DeqpResults, PatternsMatchAnywhereInTheName) {
  const fs::path f = writeFile("flakes", "# known flakes\n\nsoftpipe\n^shading/.*@gl:egl:zink$\n");
  const RunnerPatterns p = readRunnerPatterns(f);
  EXPECT_EQ(p.patterns.size(), 2u);
  EXPECT_TRUE(p.matches("zbuffer/a@gl:egl:softpipe"));
  EXPECT_TRUE(p.matches("shading/sphere@gl:egl:zink"));
  EXPECT_FALSE(p.matches("x/shading/sphere@gl:egl:zink"));
  EXPECT_FALSE(p.matches("shading/sphere@gl:egl:llvmpipe"));
  const fs::path bad = writeFile("badre", "ok\n(unclosed\n");
  EXPECT_NE(errorOf([&] { readRunnerPatterns(bad); }).find(bad.string() + ":2: \"(unclosed\""),
            std::string::npos);
}

TEST(DeqpResults, CsvFilesAreSortedAndSayEveryStatus) {
  Report report;
  PairResult b = row("b", Status::Fail);
  b.render_seconds = 0.5;
  b.seconds = 0.25;
  report.results.push_back(b);
  report.results.push_back(row("a", Status::Pass));
  report.results.push_back(row("c", Status::Flake));
  report.skipped = {"0skipped@gl:x"};
  EXPECT_EQ(resultsCsv(report),
            "0skipped@gl:x,Skip,0\na@gl:x,Pass,0\nb@gl:x,Fail,0.75\nc@gl:x,Flake,0\n");
  EXPECT_EQ(failuresCsv(report), "b@gl:x,Fail\n");
  EXPECT_EQ(exitCodeFor(report), 1);
}

// A baseline applied: expected failures, an unexpected pass, a new failure, a known flake;
// the exit code says whether the run matches.
TEST(DeqpResults, AppliedFilesDecideTheExitCode) {
  Report report;
  report.results = {row("fails", Status::Fail), row("fixed", Status::Pass),
                    row("new", Status::Fail), row("flaky", Status::Fail),
                    row("steady", Status::Pass)};
  RunnerFiles files;
  files.baseline_file = "fails.txt";
  files.baseline.expected = {{"fails@gl:x", "Fail"}, {"fixed@gl:x", "Fail"}};
  files.flakes_file = "flakes.txt";
  files.flakes.patterns = {"^flaky@"};
  files.flakes.compiled.emplace_back("^flaky@");
  applyRunnerFiles(files, report);
  EXPECT_EQ(report.results[0].runner_status, "ExpectedFail");
  EXPECT_EQ(report.results[1].runner_status, "UnexpectedPass");
  EXPECT_EQ(report.results[2].runner_status, "Fail");
  EXPECT_EQ(report.results[3].runner_status, "KnownFlake");
  EXPECT_EQ(report.results[4].runner_status, "Pass");
  EXPECT_EQ(report.runner["matches_baseline"], false);
  EXPECT_EQ(report.runner["unexpected"], 2);
  EXPECT_EQ(exitCodeFor(report), 1);
  EXPECT_EQ(failuresCsv(report), "fixed@gl:x,UnexpectedPass\nnew@gl:x,Fail\n");

  // The same run with its failures as the baseline (deqp-runner's round trip) matches,
  // however many a flake: exit 0.
  RunnerFiles again;
  again.baseline_file = "results.csv";
  again.baseline.expected = {
      {"fails@gl:x", "Fail"}, {"new@gl:x", "Fail"}, {"flaky@gl:x", "Fail"}, {"fixed@gl:x", "Pass"}};
  for (PairResult& r : report.results) r.runner_status.clear();
  applyRunnerFiles(again, report);
  EXPECT_EQ(report.runner["matches_baseline"], true);
  EXPECT_EQ(exitCodeFor(report), 0);

  // An unexpected crash is exit 3, as a backend that could not run.
  report.results.push_back(row("crash", Status::Error));
  report.results.back().error = "crashed (Segmentation fault)";
  applyRunnerFiles(again, report);
  EXPECT_EQ(report.results.back().runner_status, "Crash");
  EXPECT_EQ(exitCodeFor(report), 3);
}

}  // namespace
}  // namespace rc
