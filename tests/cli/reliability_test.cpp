// "Nothing lost, ever" (docs/reliability.md) as a user meets it: a command killed at any
// rename, unlink or write leaves its output folder either as it was or whole and new,
// and the next command removes what the killed one left; a failing command (bad input,
// a full disk) creates nothing; every refusal is one safe line naming the file and the
// JSON path; report folders are unique whatever the fixture names; OBJ attribute indices
// are checked; renders over the resource limits are refused with the estimate.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/subprocess.h"
#include "tests/support/command.h"

namespace fs = std::filesystem;

namespace {

using Result = rc::test::CommandResult;

Result run(const std::string& args, bool separate_err = false) {
  return rc::test::runShell(RC_EXE " " + args, separate_err);
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_rel_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string catalog(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/fixtures/scenes/" + rel;
}

std::string readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary) << bytes;
}

// Every regular file under `dir`, by relative path, with its bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = readBytes(e.path());
  return files;
}

std::set<std::string> names(const std::map<std::string, std::string>& files) {
  std::set<std::string> out;
  for (const auto& [name, bytes] : files) out.insert(name);
  return out;
}

// Staging folders (of this tool, of any version) directly in `dir`.
std::vector<std::string> stagingIn(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(".rastercheck-", 0) == 0 || n.find(".tmp-") != std::string::npos) out.push_back(n);
  }
  return out;
}

bool straceWorks() { return rc::test::runShell("strace -f -qq -o /dev/null true").code == 0; }

// Runs `args` under strace, killing the process (SIGKILL) at the k-th call of any of
// `calls` (strace counts per thread and child process). Returns the exit code (137 when
// killed).
int killAt(const std::string& calls, int k, const std::string& args) {
  const std::string strace = "strace -f -qq -o /dev/null -e trace=" + calls +
                             " -e inject=" + calls + ":signal=KILL:when=" + std::to_string(k);
  return rc::test::runShell(strace + " " RC_EXE " " + args + " >/dev/null 2>&1").code;
}

// A report folder is whole when its report.json parses, names `fixture`, and every image
// it names exists; junit.xml and report.html are complete documents.
::testing::AssertionResult wholeReport(const fs::path& out, const std::string& fixture) {
  nlohmann::json j = nlohmann::json::parse(readBytes(out / "report.json"), nullptr, false);
  if (j.is_discarded() || !j.contains("results") || j["results"].empty())
    return ::testing::AssertionFailure() << "report.json missing or unreadable";
  for (const auto& row : j["results"]) {
    if (row.value("fixture", "") != fixture)
      return ::testing::AssertionFailure() << "report.json names " << row.value("fixture", "");
    for (const auto& [kind, rel] : row["images"].items())
      if (!fs::is_regular_file(out / rel.get<std::string>()))
        return ::testing::AssertionFailure() << "missing " << rel;
  }
  const std::string junit = readBytes(out / "junit.xml");
  const std::string html = readBytes(out / "report.html");
  if (junit.find("</testsuites>") == std::string::npos)
    return ::testing::AssertionFailure() << "junit.xml incomplete";
  if (html.find("</html>") == std::string::npos)
    return ::testing::AssertionFailure() << "report.html incomplete";
  return ::testing::AssertionSuccess();
}

// Renders `fixture` with `backend` into `out`.
void render(const std::string& fixture, const std::string& backend, const fs::path& out) {
  const Result r = run("render " + fixture + " --backend " + backend + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
}

}  // namespace

// Kill `compare` at every rename and unlink it makes (and at a sample of its writes): the
// report folder is always the old report byte for byte, or the new one whole; the next
// compare removes the staging folder a killed one left.
TEST(Reliability, KillingCompareAnywhereLeavesTheOldOrTheNewReport) {
  if (!straceWorks()) GTEST_SKIP() << "strace cannot trace here";
  const fs::path dir = scratch("kill_compare");
  const std::string f1 = catalog("coverage/triangle_fan.json");
  const std::string f2 = catalog("coverage/jittered_grid.json");
  render(f1, "ref", dir / "a1");
  render(f1, "ref:subpixel=4", dir / "b1");
  render(f2, "ref", dir / "a2");
  render(f2, "ref:subpixel=4", dir / "b2");
  const fs::path out = dir / "reports" / "out";
  ASSERT_LE(run("compare " + (dir / "a1").string() + " " + (dir / "b1").string() + " --out " +
                out.string())
                .code,
            1);
  const auto old_files = snapshot(out);
  fs::copy(out, dir / "old", fs::copy_options::recursive);
  const std::string args =
      "compare " + (dir / "a2").string() + " " + (dir / "b2").string() + " --out " + out.string();
  ASSERT_LE(run(args.substr(0, args.size() - out.string().size()) + (dir / "new").string()).code,
            1);
  const std::set<std::string> new_names = names(snapshot(dir / "new"));

  int kills = 0;
  int saw_old = 0;
  int saw_new = 0;
  auto check = [&](const std::string& where) {
    const auto now = snapshot(out);
    if (now == old_files) {
      ++saw_old;
    } else {
      EXPECT_EQ(names(now), new_names) << where;
      EXPECT_TRUE(wholeReport(out, "coverage/jittered_grid")) << where;
      ++saw_new;
    }
    fs::remove_all(out);
    fs::copy(dir / "old", out, fs::copy_options::recursive);
  };
  for (const std::string calls : {"rename,renameat,renameat2,unlink,unlinkat,rmdir"}) {
    for (int k = 1; k < 200; ++k) {
      const int code = killAt(calls, k, args);
      if (code != 137) {  // fewer calls than k: ran to the end
        EXPECT_LE(code, 1);
        break;
      }
      ++kills;
      check(calls + " #" + std::to_string(k));
    }
  }
  // Writes: every 7th (there are a few hundred; each lands in the staging folder).
  for (int k = 1; k < 2000; k += 7) {
    const int code = killAt("write,writev,pwrite64", k, args);
    if (code != 137) break;
    ++kills;
    check("write #" + std::to_string(k));
  }
  // The figures docs/reliability.md quotes (--gtest_output=json shows them).
  RecordProperty("kills", kills);
  RecordProperty("old_report", saw_old);
  RecordProperty("new_report", saw_new);
  EXPECT_GT(kills, 10);
  EXPECT_GT(saw_old, 0);
  EXPECT_GT(saw_new, 0) << "no kill came after the swap: the test did not reach the commit";
  // Killed commands left staging folders; one more compare removes them all.
  EXPECT_LE(run(args).code, 1);
  EXPECT_TRUE(wholeReport(out, "coverage/jittered_grid"));
  EXPECT_EQ(stagingIn(out.parent_path()), std::vector<std::string>{});
  fs::remove_all(dir);
}

// The same for `render` and its frame folder, and for `run`, whose renders run in child
// processes (killed at their own renames too: then the new report has an error row, but
// is whole).
TEST(Reliability, KillingRenderOrRunAtEveryRenameLeavesTheOldOrTheNewOutput) {
  if (!straceWorks()) GTEST_SKIP() << "strace cannot trace here";
  const fs::path dir = scratch("kill_render");
  const fs::path frame = dir / "frame";
  render(catalog("coverage/triangle_fan.json"), "ref", frame);
  const auto old_frame = snapshot(frame);
  render(catalog("coverage/jittered_grid.json"), "ref", dir / "new_frame");
  // frame.json holds the time taken: the images identify a frame, frame.json's fixture.
  auto sameFrame = [](std::map<std::string, std::string> a, std::map<std::string, std::string> b) {
    if (names(a) != names(b)) return false;
    const auto fixture = [](const std::string& text) {
      return nlohmann::json::parse(text, nullptr, false).value("fixture", "?");
    };
    if (fixture(a["frame.json"]) != fixture(b["frame.json"])) return false;
    a.erase("frame.json");
    b.erase("frame.json");
    return a == b;
  };
  const auto new_frame = snapshot(dir / "new_frame");
  const std::string calls = "rename,renameat,renameat2,unlink,unlinkat,rmdir";
  const std::string render_args =
      "render " + catalog("coverage/jittered_grid.json") + " --backend ref --out " + frame.string();
  int kills = 0;
  int render_old = 0;
  for (int k = 1; k < 100; ++k) {
    const int code = killAt(calls, k, render_args);
    if (code != 137) break;
    ++kills;
    const auto now = snapshot(frame);
    if (now == old_frame) ++render_old;
    EXPECT_TRUE(now == old_frame || sameFrame(now, new_frame)) << "render killed at call " << k;
    fs::remove_all(frame);
    fs::copy(dir / "new_frame", frame);  // alternate: the next run replaces the new one
    for (const auto& [name, bytes] : old_frame) writeBytes(frame / name, bytes);
  }
  RecordProperty("render_kills", kills);
  RecordProperty("render_old_frame", render_old);
  EXPECT_GT(kills, 1);

  const fs::path out = dir / "runs" / "out";
  const std::string fixture = catalog("coverage/triangle_fan.json");
  ASSERT_EQ(
      run("run " + fixture + " --backends ref:subpixel=8 --jobs 1 --out " + out.string()).code, 0);
  fs::copy(out, dir / "old_run", fs::copy_options::recursive);
  const auto old_run = snapshot(out);
  const std::string run_args = "run " + catalog("coverage/jittered_grid.json") +
                               " --backends ref:subpixel=8 --jobs 1 --out " + out.string();
  kills = 0;
  int run_new = 0;
  for (int k = 1; k < 100; ++k) {
    const int code = killAt(calls, k, run_args);
    if (code != 137) break;
    ++kills;
    if (snapshot(out) != old_run) {
      ++run_new;
      EXPECT_TRUE(wholeReport(out, "coverage/jittered_grid")) << "run killed at call " << k;
    }
    fs::remove_all(out);
    fs::copy(dir / "old_run", out, fs::copy_options::recursive);
  }
  RecordProperty("run_kills", kills);
  RecordProperty("run_new_report", run_new);
  EXPECT_GT(kills, 1);
  EXPECT_EQ(run(run_args).code, 0);
  EXPECT_EQ(stagingIn(out.parent_path()), std::vector<std::string>{});
  fs::remove_all(dir);
}

// A run killed while it renders leaves its staging folder; the next run in the same place
// removes it, and the output folder never appeared.
TEST(Reliability, ADeadRunsStagingIsRemovedByTheNextRun) {
  const fs::path dir = scratch("dead_run");
  const fs::path out = dir / "out";
  const std::string args =
      "run " + catalog("") + " --backends ref:subpixel=4 --jobs 1 --out " + out.string();
  // Killed once it has begun rendering (its staging folder exists), long before the
  // catalog is done: the whole catalog (60 fixtures), since the three of coverage/ were
  // sometimes all done within the 0.3 s (a run that ends by itself leaves no staging).
  const Result killed = rc::test::runShell(
      "sh -c '" RC_EXE " " + args +
      " >/dev/null 2>&1 & p=$!; i=0; while [ $i -lt 600 ] && ! ls -A " + dir.string() +
      " | grep -q rastercheck-staging; do sleep 0.05; i=$((i+1)); done; " +
      "sleep 0.3; kill -9 $p; wait $p; echo $?'");
  EXPECT_EQ(killed.out.substr(killed.out.size() - 4), "137\n") << killed.out;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(stagingIn(dir).size(), 1u);
  EXPECT_EQ(run("run " + catalog("coverage/triangle_fan.json") +
                " --backends ref:subpixel=8 --out " + out.string())
                .code,
            0);
  EXPECT_EQ(stagingIn(dir), std::vector<std::string>{});
  fs::remove_all(dir);
}

// A cancelled job (a campaign's run on Ctrl-C) is over only when everything it started is:
// its children share its open files (the staging folder's lock) and write into its folder
// after it has died, so the campaign's clean-up waits for them. One child of the job
// outlives it by 0.5 s and then writes; another ignores SIGTERM and must be killed.
TEST(Reliability, ACancelledJobEndsWithEverythingItStarted) {
  const fs::path dir = scratch("cancel_group");
  const fs::path ready = dir / "ready";
  const fs::path late = dir / "late";
  const fs::path stubborn = dir / "stubborn.pid";
  rc::Job job;
  job.argv = {"/bin/sh", "-c",
              "(trap '' TERM; sleep 0.5; echo late > " + late.string() + ") & " +
                  "(trap '' TERM; echo $(exec sh -c 'echo $PPID') > " + stubborn.string() +
                  "; while :; do sleep 0.05; done) & " + "sleep 0.2; touch " + ready.string() +
                  "; exec sleep 60"};
  job.log = dir / "job.log";
  std::vector<rc::Job> jobs{job};
  std::atomic<bool> cancel{false};
  rc::JobControl control;
  control.cancel = &cancel;
  control.own_process_group = true;
  control.tick_seconds = 0.02;
  control.on_tick = [&] {
    if (fs::exists(ready)) cancel = true;
  };
  const auto start = std::chrono::steady_clock::now();
  rc::runJobs(jobs, 1, {}, {}, control);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(jobs[0].cancelled);
  EXPECT_EQ(jobs[0].exit_code, 128 + SIGTERM);
  EXPECT_TRUE(fs::exists(late)) << "runJobs returned before the job's child had finished";
  const long pid = std::stol(readBytes(stubborn));
  ASSERT_GT(pid, 1);
  // Gone, or a zombie until the init process reaps it.
  const std::string stat = readBytes("/proc/" + std::to_string(pid) + "/stat");
  const std::size_t close = stat.rfind(')');
  EXPECT_TRUE(close == std::string::npos || stat.substr(close + 2, 1) == "Z")
      << "the child that ignores SIGTERM is still running: " << stat;
  EXPECT_LT(seconds, 10.0);
  fs::remove_all(dir);
}

// Bad input, a backend that cannot start, a full disk: nothing is created, not even the
// folders above --out, and an earlier output stays as it was.
TEST(Reliability, AFailingCommandCreatesNothing) {
  const fs::path dir = scratch("fail_nothing");
  const fs::path deep = dir / "new" / "deeper" / "out";
  const std::string fan = catalog("coverage/triangle_fan.json");
  EXPECT_EQ(run("run " + fan + " --backends vulkan --out " + deep.string()).code, 2);
  EXPECT_EQ(run("render " + fan + " --backend gl:egl-device:7 --out " + deep.string()).code, 3);
  EXPECT_EQ(run("compare " + dir.string() + " " + dir.string() + " --out " + deep.string()).code,
            2);
  EXPECT_FALSE(fs::exists(dir / "new"));

  // A full disk, as a file size limit: every write past 64 kB fails with EFBIG (the kept
  // frames are larger).
  const fs::path out = dir / "out";
  ASSERT_EQ(run("run " + fan + " --backends ref:subpixel=8 --out " + out.string()).code, 0);
  const auto before = snapshot(out);
  const Result full =
      rc::test::runShell("sh -c 'trap \"\" XFSZ; ulimit -f 64; exec " RC_EXE " run " +
                         catalog("coverage/jittered_grid.json") +
                         " --backends ref:subpixel=8 --keep-frames --out " + out.string() + "'");
  EXPECT_EQ(full.code, 2) << full.out;
  EXPECT_EQ(snapshot(out), before);
  EXPECT_EQ(stagingIn(dir), std::vector<std::string>{});
  EXPECT_FALSE(fs::exists(out / "variants"));
  fs::remove_all(dir);
}

namespace {

// A fixture with `body` spliced into an otherwise valid scene.
std::string scene(const std::string& extra) {
  return R"({"format": "rastercheck-scene/1", "image": {"width": 8, "height": 8},
    "camera": {"eye": [0, 0, 5]}, "objects": [{"mesh": {"generator": "cube"}}])" +
         extra + "}";
}

// Runs `render` on `text` (written to dir/name) and checks the promise: exit 2, nothing on
// stdout, exactly one line on stderr of valid UTF-8 without control characters, at most
// ~1 kB, naming the file and `mention`.
void expectOneLine(const fs::path& dir, const std::string& name, const std::string& text,
                   const std::string& mention, const std::string& shown_name = "") {
  const fs::path file = dir / name;
  writeBytes(file, text);
  const Result r =
      run("render '" + file.string() + "' --backend ref --out " + (dir / "o").string(), true);
  SCOPED_TRACE(name);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.out, "");
  ASSERT_FALSE(r.err.empty());
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.back(), '\n');
  for (const char c : r.err.substr(0, r.err.size() - 1))
    EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << "control byte in " << r.err;
  EXPECT_LE(r.err.size(), 1100u);
  EXPECT_NE(r.err.find(shown_name.empty() ? name : shown_name), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(mention), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  // Valid UTF-8 (nlohmann refuses anything else).
  EXPECT_NO_THROW((void)nlohmann::json(r.err).dump()) << r.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
}

}  // namespace

TEST(Reliability, EveryRefusalIsOneSafeLine) {
  const fs::path dir = scratch("lines");
  // A wrong-type string of multi-byte characters, longer than the 40 bytes shown, with the
  // 40th byte inside a character.
  std::string long_utf8;
  for (int i = 0; i < 30; ++i) long_utf8 += "\xc3\xa9";
  expectOneLine(dir, "utf8.json",
                scene(R"(, "name": ")" + long_utf8 + R"(", "tags": "x)" + long_utf8 + "\""),
                "tags: expected an array");
  expectOneLine(dir, "newline_key.json", scene(R"(, "state": {"shad\ning": "flat"})"),
                R"(state["shad\ning"]: unknown key)");
  expectOneLine(dir, "nul_key.json", scene(R"(, "state": {"a\u0000b": 1})"), R"(state["a\0b"])");
  expectOneLine(dir, "long_key.json", scene(", \"" + std::string(100000, 'k') + "\": 1"),
                "unknown key");
  expectOneLine(dir, "bidi.json", scene(R"(, "state": {"shading": "\u202eflat"})"),
                "\\u{202e}flat");
  expectOneLine(dir, "escape.json", scene(R"(, "name": 7, "description": "\u001b[2J")"), "name");
  // A truncated PNG: libpng's own words go into our line, not beside it.
  const std::string png = readBytes(catalog("textures/checker.png"));
  writeBytes(dir / "cut.png", png.substr(0, png.size() / 2));
  expectOneLine(dir, "cut_png.json",
                R"({"format": "rastercheck-scene/1", "image": {"width": 8, "height": 8},
    "camera": {"eye": [0, 0, 5]}, "materials": {"m": {"texture": "cut.png"}},
    "objects": [{"material": "m", "mesh": {"generator": "cube"}}]})",
                "materials.m.texture");
  // A file name with a newline in it.
  expectOneLine(dir, "bad\nname.json", "{", "invalid JSON", "bad\\nname.json");
  fs::remove_all(dir);
}

// An ASE file on which Assimp 5.2 segfaults inside ReadFile (found by fuzz_mesh): the
// import runs in a child process, so `render` refuses it with one line (it exited 139).
TEST(Reliability, AMeshFileThatCrashesAssimpIsOneLine) {
  const fs::path dir = scratch("assimp_crash");
  const std::string found =
      readBytes(fs::path(RC_SOURCE_DIR) / "tests/fuzz/regressions/mesh/ase-segv-in-assimp");
  writeBytes(dir / "crash.ase", found.substr(1));  // the fuzz input's first byte: the format
  expectOneLine(dir, "crash.json",
                R"({"format": "rastercheck-scene/1", "image": {"width": 8, "height": 8},
    "camera": {"eye": [0, 0, 5]}, "objects": [{"mesh": {"file": "crash.ase"}}]})",
#ifdef RC_SANITIZER_BUILD
                // ASan in the instrumented child catches the segfault inside libassimp
                // (MeshImport.AnImporterCrashIsAnInputErrorNamingTheFile).
                "AddressSanitizer: SEGV",
#else
                "the mesh importer crashed (signal 11",
#endif
                "crash.ase");
  fs::remove_all(dir);
}

TEST(Reliability, ReportFoldersAreUniqueWhateverTheNames) {
  const fs::path dir = scratch("unique");
  int k = 0;
  for (const std::string name : {"dup/a b", "dup/a_b", "dup/a?b"})
    writeBytes(dir / ("f" + std::to_string(k++) + ".json"), scene(R"(, "name": ")" + name + "\""));
  const fs::path out = dir / "out";
  // --keep-frames: passing pairs get their images (and folders) too.
  const Result r =
      run("run " + dir.string() + " --backends ref:subpixel=4 --keep-frames --out " + out.string());
  ASSERT_LE(r.code, 1) << r.out;
  const nlohmann::json j = nlohmann::json::parse(readBytes(out / "report.json"));
  std::set<std::string> folders;
  for (const auto& row : j.at("results")) {
    const std::string img = row.at("images").at("visibility").get<std::string>();
    folders.insert(fs::path(img).parent_path().string());
    EXPECT_TRUE(fs::is_regular_file(out / img)) << img;
  }
  EXPECT_EQ(folders.size(), 3u);
  fs::remove_all(dir);
}

TEST(Reliability, ObjAttributeIndicesAreChecked) {
  const fs::path dir = scratch("obj");
  auto objScene = [&](const std::string& obj_name, const std::string& obj) {
    writeBytes(dir / obj_name, obj);
    return R"({"format": "rastercheck-scene/1", "image": {"width": 8, "height": 8},
      "camera": {"eye": [0, 0, 5]}, "objects": [{"mesh": {"file": ")" +
           obj_name + R"("}}]})";
  };
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expectOneLine(dir, "uv.json", objScene("uv.obj", v + "vt 0 0\nf 1/5 2/1 3/1\n"),
                "texture coordinate index 5 is out of range");
  expectOneLine(dir, "normal.json", objScene("normal.obj", v + "vn 0 0 1\nf 1//7 2//1 3//1\n"),
                "normal index 7 is out of range");
  expectOneLine(dir, "negative.json", objScene("negative.obj", v + "vn 0 0 1\nf 1//-2 2//1 3//1\n"),
                "normal index -2 is out of range");
  expectOneLine(dir, "zero.json", objScene("zero.obj", v + "f 0 1 2\n"), "index 0");
  // In range, forwards and backwards: renders.
  writeBytes(dir / "ok.json", objScene("ok.obj", v + "vt 0 0\nvn 0 0 1\nf 1/1/1 2/-1/-1 3/1/1\n"));
  EXPECT_EQ(
      run("render " + (dir / "ok.json").string() + " --backend ref --out " + (dir / "ok").string())
          .code,
      0);
  fs::remove_all(dir);
}

TEST(Reliability, RendersOverTheLimitsAreRefusedWithTheEstimate) {
  const fs::path dir = scratch("limits");
  writeBytes(dir / "huge.json", R"({"format": "rastercheck-scene/1",
    "image": {"width": 16384, "height": 4096}, "camera": {"eye": [0, 0, 5]},
    "objects": [{"mesh": {"generator": "cube"}}]})");
  Result r = run("render " + (dir / "huge.json").string() +
                     " --backend ref --max-memory 1G --out " + (dir / "o").string(),
                 true);
  EXPECT_EQ(r.code, 2) << r.err;
  // Measured peak 6.4e9 B (docs/reliability.md, "Resource limits").
  EXPECT_NE(r.err.find("needs about 6.1 GiB"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("16384x4096"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--max-memory"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
  // 300,000 lights on a sphere filling a third of 512x512 pixels: about 9e10 light
  // evaluations, refused by default (1e10), and by `run` before it renders anything.
  std::string lights;
  for (int i = 0; i < 300000; ++i)
    lights += std::string(i ? "," : "") + R"({"type": "point", "position": [1, 1, 1]})";
  writeBytes(dir / "lights.json", R"({"format": "rastercheck-scene/1",
    "image": {"width": 512, "height": 512}, "camera": {"eye": [0, 0, 3]},
    "lights": [)" + lights + R"(], "objects": [{"mesh": {"generator": "sphere"}}]})");
  r = run("run " + (dir / "lights.json").string() + " --backends ref:subpixel=4 --out " +
              (dir / "o").string(),
          true);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("300000 lights"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--max-work"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
  fs::remove_all(dir);
}
