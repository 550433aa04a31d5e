// Known driver differences (compare/expectations.h): the file format's errors, and which
// pairs an entry covers: by fixture glob, backend pattern, driver version and render
// state, so that a known difference does not hide another failure.
#include <gtest/gtest.h>

#include <string>

#include "compare/expectations.h"
#include "fixtures/errors.h"

namespace rc {
namespace {

using nlohmann::json;

TEST(Globs, StarAndQuestionMark) {
  EXPECT_TRUE(globMatches("*", ""));
  EXPECT_TRUE(globMatches("*", "random/s1/0004"));
  EXPECT_TRUE(globMatches("random/*", "random/s1/0004"));
  EXPECT_TRUE(globMatches("*Mesa 22.*", "3.3 (Core Profile) Mesa 22.3.6"));
  EXPECT_FALSE(globMatches("*Mesa 23.*", "3.3 (Core Profile) Mesa 22.3.6"));
  EXPECT_TRUE(globMatches("depth/zfight_?16", "depth/zfight_d16"));
  EXPECT_FALSE(globMatches("depth/zfight_?16", "depth/zfight_d160"));
  EXPECT_TRUE(globMatches("a*b*c", "aXXbYYc"));
  EXPECT_FALSE(globMatches("a*b*c", "aXXbYY"));
  EXPECT_TRUE(backendMatches("gl:*:softpipe", "gl:egl:softpipe"));
  EXPECT_TRUE(backendMatches("gl:*:softpipe", "gl:osmesa:softpipe"));
  EXPECT_FALSE(backendMatches("gl:*:softpipe", "gl:egl:llvmpipe"));
  EXPECT_FALSE(backendMatches("gl:*", "gl:egl:softpipe"));  // one part per '*'
}

Expectations softpipeD16() {
  return parseExpectations(json::parse(R"({"expectations": [
      {"id": "z16", "fixture": "*", "backend": "gl:*:softpipe", "driver_version": "*Mesa 22.*",
       "state": {"depth_format": "d16"}, "class": "depth", "reason": "the Z16 fast path"}]})"),
                           "test.json");
}

PairResult failingPair(const std::string& fixture, const std::string& backend,
                       const std::string& depth_format) {
  PairResult r;
  r.fixture = fixture;
  r.expected = "ref";
  r.actual = backend;
  r.actual_driver = "3.3 (Core Profile) Mesa 22.3.6";
  r.state = {{"depth_format", depth_format}, {"depth_test", true}};
  r.status = Status::Fail;
  r.depth.status = Status::Fail;
  return r;
}

TEST(Expectations, AScopedEntryCoversOnlyItsDriverAndState) {
  const Expectations x = softpipeD16();
  ASSERT_EQ(x.entries.size(), 1u);
  EXPECT_FALSE(x.entries[0].strict);  // a pattern: may fail, need not
  Report report;
  report.results.push_back(failingPair("random/s1/0004", "gl:egl:softpipe", "d16"));  // covered
  report.results.push_back(failingPair("random/s1/0005", "gl:egl:softpipe", "d24"));  // state
  report.results.push_back(failingPair("random/s1/0006", "gl:egl:llvmpipe", "d16"));  // driver
  PairResult other_version = failingPair("random/s1/0007", "gl:egl:softpipe", "d16");
  other_version.actual_driver = "4.5 (Core Profile) Mesa 24.0.1";
  report.results.push_back(other_version);
  PairResult shading_too = failingPair("random/s1/0008", "gl:egl:softpipe", "d16");
  shading_too.shading.status = Status::Fail;  // a second failing class nobody expects
  report.results.push_back(shading_too);
  applyExpectations(x, report);
  EXPECT_EQ(report.results[0].known.size(), 1u);
  EXPECT_EQ(report.results[0].known[0].id, "z16");
  for (std::size_t i = 1; i < report.results.size(); ++i)
    EXPECT_TRUE(report.results[i].known.empty()) << report.results[i].fixture;
  EXPECT_EQ(report.summary().known_fail, 1u);
  EXPECT_EQ(exitCodeFor(report), 1);  // four failures nobody expects
  report.results.resize(1);
  EXPECT_EQ(exitCodeFor(report), 0);  // only the known one
  const json j = toJson(report, ".");
  EXPECT_EQ(j["summary"]["known_fail"], 1);
  EXPECT_EQ(j["results"][0]["known"][0]["id"], "z16");
  EXPECT_EQ(j["results"][0]["state"]["depth_format"], "d16");
}

TEST(Expectations, AnEntryNamingOneFixtureIsStrictUnlessSaidOtherwise) {
  const Expectations x = parseExpectations(json::parse(R"({"expectations": [
      {"fixture": "depth/a", "backend": "gl:egl:softpipe", "class": "depth", "reason": "r"},
      {"fixture": "depth/b", "backend": "gl:egl:softpipe", "class": "depth", "reason": "r",
       "strict": false}]})"),
                                           "t");
  EXPECT_TRUE(x.entries[0].strict);
  EXPECT_FALSE(x.entries[1].strict);
  EXPECT_EQ(x.entries[0].id, "expectations[0]");  // without an id, its place in the file
}

TEST(Expectations, EachMistakeIsOneLineNamingItsPath) {
  const std::vector<std::pair<const char*, const char*>> cases = {
      {R"({"expectations": [{"fixture": "*", "backend": "gl:egl:softpipe", "class": "colour",
          "reason": "r"}]})",
       "t.json: expectations[0].class: \"colour\" is not one of"},
      {R"({"expectations": [{"fixture": "*", "backend": "gl:egl:softpipe", "class": "depth",
          "reason": " "}]})",
       "t.json: expectations[0].reason: must say why"},
      {R"({"expectations": [{"fixture": "*", "backend": "gl:egl:softpipe", "class": "depth"}]})",
       "t.json: expectations[0].reason: missing"},
      {R"({"expectations": [{"fixture": "*", "backend": "gl:egl:softpipe", "class": "depth",
          "reason": "r", "why": 1}]})",
       "t.json: expectations[0].why: unknown key"},
      {R"({"expectations": [{"fixture": "*", "backend": 3, "class": "depth", "reason": "r"}]})",
       "t.json: expectations[0].backend: must be a string"},
      {R"({"expectations": [{"fixture": "*", "backend": "b", "class": "depth", "reason": "r",
          "state": {"depth_fmt": "d16"}}]})",
       "t.json: expectations[0].state.depth_fmt: not a render state key"},
      {R"({"expectations": [{"fixture": "*", "backend": "b", "class": "depth", "reason": "r",
          "state": {"depth_format": 16}}]})",
       "t.json: expectations[0].state.depth_format: must be a string or a boolean"},
      {R"({"expectations": [{"id": "x", "fixture": "*", "backend": "b", "class": "depth",
          "reason": "r"}, {"id": "x", "fixture": "a", "backend": "b", "class": "depth",
          "reason": "r"}]})",
       "t.json: expectations[1].id: repeats \"x\""},
      {R"({"expectations": [{"fixture": "*", "backend": "b", "class": "depth", "reason": "r",
          "tags": "texture"}]})",
       "t.json: expectations[0].tags: must be a non-empty array of tags"},
      {R"({"expectations": [{"fixture": "*", "backend": "b", "class": "depth", "reason": "r",
          "tags": []}]})",
       "t.json: expectations[0].tags: must be a non-empty array of tags"},
      {R"({"expectations": [{"fixture": "*", "backend": "b", "class": "depth", "reason": "r",
          "tags": ["texture", 3]}]})",
       "t.json: expectations[0].tags[1]: must be a non-empty string"},
      {R"({"expectations": [7]})", "t.json: expectations[0]: must be an object"},
      {R"({"expectation": []})", "t.json: expectation: unknown key"},
      {R"({"expectations": {}})", "t.json: expectations: must be an array"},
  };
  for (const auto& [text, want] : cases) {
    try {
      parseExpectations(json::parse(text), "t.json");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos)
          << e.what() << "\nwanted: " << want;
    }
  }
}

TEST(Expectations, BooleanStateValuesMatchTheFixturesBooleans) {
  const Expectations x = parseExpectations(json::parse(R"({"expectations": [
      {"fixture": "*", "backend": "gl:egl:softpipe", "state": {"depth_test": false},
       "class": "depth", "reason": "r"}]})"),
                                           "t");
  PairContext pair;
  pair.fixture = "f";
  pair.backend = "gl:egl:softpipe";
  pair.state = {{"depth_test", false}};
  EXPECT_TRUE(covers(x.entries[0], pair));
  pair.state = {{"depth_test", true}};
  EXPECT_FALSE(covers(x.entries[0], pair));
  pair.state = json::object();  // a pair without state (an old frame) is not covered
  EXPECT_FALSE(covers(x.entries[0], pair));
}

// An entry with tags covers a pair only when the fixture carries every one of them (and
// run's reports carry the fixture's tags through to the matcher).
TEST(Expectations, TagsMustAllBeOnTheFixture) {
  const Expectations x = parseExpectations(json::parse(R"({"expectations": [
      {"id": "wide", "fixture": "*", "backend": "gl:*:softpipe", "state": {"blend": "alpha"},
       "tags": ["texture", "clear:wide-color"], "class": "shading", "reason": "r"}]})"),
                                           "t");
  ASSERT_EQ(x.entries[0].tags.size(), 2u);
  PairContext pair;
  pair.fixture = "random/s1/0001";
  pair.backend = "gl:egl:softpipe";
  pair.state = {{"blend", "alpha"}};
  pair.tags = {"random", "clear:wide-color", "texture"};
  EXPECT_TRUE(covers(x.entries[0], pair));
  pair.tags = {"random", "texture"};  // one tag missing
  EXPECT_FALSE(covers(x.entries[0], pair));
  pair.tags = {};
  EXPECT_FALSE(covers(x.entries[0], pair));
  PairResult r;
  r.fixture = "random/s1/0001";
  r.actual = "gl:osmesa:softpipe";
  r.state = {{"blend", "alpha"}};
  r.tags = {"texture", "clear:wide-color"};
  r.status = Status::Fail;
  r.shading.status = Status::Fail;
  ASSERT_EQ(knownFailuresOf(x, r).size(), 1u);
  r.tags.pop_back();
  EXPECT_TRUE(knownFailuresOf(x, r).empty());
}

}  // namespace
}  // namespace rc
