// `rastercheck campaign` refusing what it cannot do, before any rendering: one line on
// stderr, exit code 2, and no folder made or changed. No GL driver is needed.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/support/command.h"

namespace fs = std::filesystem;
using ::testing::HasSubstr;

namespace {

rc::test::CommandResult campaign(const std::string& args) {
  return rc::test::runShell(RC_EXE " campaign " + args, /*separate_err=*/true);
}

fs::path scratch(const std::string& name) {
  fs::path p =
      fs::temp_directory_path() / ("rc_campaign_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  return p;
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

void expectRefused(const std::string& args, const std::string& message) {
  const rc::test::CommandResult r = campaign(args);
  EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr(message)) << args;
  EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
}

TEST(CampaignCli, BadArgumentsAreRefusedInOneLine) {
  const fs::path out = scratch("args");
  const std::string o = " --out " + out.string();
  expectRefused("--seed 1 --backends gl:egl:nope" + o, "gl:egl:nope");
  expectRefused("--seed -1 --backends gl:egl:llvmpipe" + o, "--seed");
  expectRefused("--seed 1 --count 0 --backends gl:egl:llvmpipe" + o, "--count");
  expectRefused("--seed 1 --backends gl:egl:llvmpipe --reduce-seconds -1" + o, "--reduce-seconds");
  expectRefused("--seed 1 --backends gl:egl:llvmpipe --batch 0" + o, "--batch");
  expectRefused("--seed 1 --backends gl:egl:llvmpipe -t depth.fial=3" + o, "depth.fial");
  expectRefused("--seed 1 --backends gl:egl:llvmpipe --faults light_scale" + o,
                "--faults: only with --mutations");
  expectRefused("--mutations --seed 1 --backends ref" + o, "name GL backends only");
  expectRefused("--mutations --seed 1 --backends gl:egl:llvmpipe --against gl:egl:softpipe" + o,
                "compares with the reference");
  expectRefused("--mutations --seed 1 --backends gl:egl:llvmpipe --faults light_scale,frob" + o,
                "unknown fault 'frob'");
  EXPECT_FALSE(fs::exists(out)) << "nothing is made for a refused command";
}

TEST(CampaignCli, FoldersThatAreNotThisCampaignsAreLeftAlone) {
  const fs::path dir = scratch("folders");
  fs::create_directories(dir);
  std::ofstream(dir / "notes.txt") << "mine\n";
  expectRefused("--seed 1 --backends gl:egl:llvmpipe --out " + dir.string(),
                "a folder that `campaign` did not write");
  expectRefused("--seed 1 --backends gl:egl:llvmpipe --out " + (dir / "notes.txt").string(),
                "names a file");
  fs::remove(dir / "notes.txt");

  // A campaign folder started with other options: the differences are named.
  std::ofstream(dir / "campaign.json") << R"({"identity": {"mode": "failures", "seed": 2,
    "profile": "all", "max_size": "200x150", "meshes": "/usr/share/assimp/models",
    "backends": ["gl:egl:llvmpipe"], "against": "ref", "tolerance": [], "batch": 20},
    "commands": []})";
  const rc::test::CommandResult r =
      campaign("--seed 1 --backends gl:egl:softpipe --out " + dir.string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("holds a campaign started with other options (backends was "
                               "[\"gl:egl:llvmpipe\"] there, [\"gl:egl:softpipe\"] now; "
                               "seed was 2 there, 1 now)"));
  EXPECT_FALSE(fs::exists(dir / "scenes"));

  // Another campaign holds the folder's lock (checked before anything else).
  const int fd = ::open((dir / ".lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  expectRefused("--seed 1 --backends gl:egl:llvmpipe --out " + dir.string(),
                "another campaign is working in this folder");
  ::close(fd);
  fs::remove_all(dir);
}

TEST(CampaignCli, HelpNamesEveryOption) {
  const rc::test::CommandResult r = rc::test::runShell(RC_EXE " campaign --help");
  EXPECT_EQ(r.code, 0);
  for (const char* option :
       {"--seed", "--count", "--backends", "--against", "--out", "--reduce-seconds", "--jobs",
        "--batch", "--profile", "--max-size", "--tolerance", "--mutations", "--faults"})
    EXPECT_THAT(r.out, HasSubstr(option));
}

}  // namespace
