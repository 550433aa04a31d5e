// Known driver differences: see expectations.h; the file format in docs/reports.md
// "Expected failures".
#include "compare/expectations.h"

#include <algorithm>
#include <fstream>
#include <set>

#include <fmt/format.h>

#include "fixtures/errors.h"

namespace rc {
namespace {

using nlohmann::json;

// The render state keys an entry may name, as the fixture format spells them.
const std::set<std::string>& stateKeys() {
  static const std::set<std::string> keys = {
      "shading",        "specular_model", "attenuation", "depth_test", "depth_format",
      "color_format",   "cull",           "front_face",  "blend",      "visibility",
      "texture_filter", "texture_wrap",   "samples"};
  return keys;
}

// A state value as a string ("true"/"false" for depth_test).
std::string stateValue(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  return v.dump();
}

[[noreturn]] void bad(const std::string& source, const std::string& path, const std::string& what) {
  throw InputError(fmt::format("{}: {}: {}", source, path, what));
}

std::string text(const json& e, const char* key, const std::string& source, const std::string& at) {
  const json& v = e.at(key);
  if (!v.is_string()) bad(source, fmt::format("{}.{}", at, key), "must be a string");
  return v.get<std::string>();
}

}  // namespace

bool globMatches(const std::string& pattern, const std::string& text) {
  // Iterative wildcard match with backtracking to the last '*'.
  std::size_t p = 0;
  std::size_t t = 0;
  std::size_t star = std::string::npos;
  std::size_t mark = 0;
  while (t < text.size()) {
    if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == text[t])) {
      ++p;
      ++t;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++;
      mark = t;
    } else if (star != std::string::npos) {
      p = star + 1;
      t = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

bool backendMatches(const std::string& pattern, const std::string& backend) {
  auto split = [](const std::string& s) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= s.size(); ++i) {
      if (i == s.size() || s[i] == ':') {
        parts.push_back(s.substr(start, i - start));
        start = i + 1;
      }
    }
    return parts;
  };
  const auto p = split(pattern);
  const auto b = split(backend);
  if (p.size() != b.size()) return false;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p[i] != "*" && p[i] != b[i]) return false;
  return true;
}

Expectations parseExpectations(const json& doc, const std::string& source) {
  if (!doc.is_object()) bad(source, "(top level)", "must be an object");
  for (const auto& [key, value] : doc.items())
    if (key != "about" && key != "expectations") bad(source, key, "unknown key");
  if (!doc.contains("expectations") || !doc["expectations"].is_array())
    bad(source, "expectations", "must be an array");
  static const std::set<std::string> classes = {"visibility", "depth", "shading"};
  static const std::set<std::string> keys = {
      "id", "fixture", "backend", "driver_version", "state", "tags", "class", "reason", "strict"};
  Expectations out;
  std::set<std::string> ids;
  const json& list = doc["expectations"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& e = list[i];
    const std::string at = fmt::format("expectations[{}]", i);
    if (!e.is_object()) bad(source, at, "must be an object");
    for (const auto& [key, value] : e.items())
      if (!keys.count(key)) bad(source, fmt::format("{}.{}", at, key), "unknown key");
    for (const char* key : {"fixture", "backend", "class", "reason"})
      if (!e.contains(key)) bad(source, fmt::format("{}.{}", at, key), "missing");
    Expectation x;
    x.fixture = text(e, "fixture", source, at);
    x.backend = text(e, "backend", source, at);
    x.cls = text(e, "class", source, at);
    x.reason = text(e, "reason", source, at);
    x.id = e.contains("id") ? text(e, "id", source, at) : at;
    if (e.contains("driver_version")) x.driver_version = text(e, "driver_version", source, at);
    if (!classes.count(x.cls))
      bad(source, at + ".class",
          fmt::format("\"{}\" is not one of visibility, depth, shading", x.cls));
    if (x.reason.find_first_not_of(" \t") == std::string::npos)
      bad(source, at + ".reason", "must say why");
    if (x.backend.empty()) bad(source, at + ".backend", "must not be empty");
    if (e.contains("state")) {
      const json& st = e["state"];
      if (!st.is_object()) bad(source, at + ".state", "must be an object");
      for (const auto& [key, value] : st.items()) {
        if (!stateKeys().count(key))
          bad(source, fmt::format("{}.state.{}", at, key), "not a render state key");
        if (!value.is_string() && !value.is_boolean())
          bad(source, fmt::format("{}.state.{}", at, key), "must be a string or a boolean");
        x.state[key] = stateValue(value);
      }
    }
    if (e.contains("tags")) {
      const json& tags = e["tags"];
      if (!tags.is_array() || tags.empty())
        bad(source, at + ".tags", "must be a non-empty array of tags");
      for (std::size_t k = 0; k < tags.size(); ++k) {
        if (!tags[k].is_string() || tags[k].get<std::string>().empty())
          bad(source, fmt::format("{}.tags[{}]", at, k), "must be a non-empty string");
        x.tags.push_back(tags[k].get<std::string>());
      }
    }
    const bool pattern = x.fixture.find_first_of("*?") != std::string::npos;
    x.strict = !pattern;
    if (e.contains("strict")) {
      if (!e["strict"].is_boolean()) bad(source, at + ".strict", "must be a boolean");
      x.strict = e["strict"].get<bool>();
    }
    if (!ids.insert(x.id).second) bad(source, at + ".id", fmt::format("repeats \"{}\"", x.id));
    out.entries.push_back(std::move(x));
  }
  return out;
}

Expectations readExpectations(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot read", file.string()));
  const json doc = json::parse(in, nullptr, false);
  if (doc.is_discarded()) throw InputError(fmt::format("{}: not valid JSON", file.string()));
  return parseExpectations(doc, file.string());
}

PairContext contextOf(const PairResult& result) {
  PairContext c;
  c.fixture = result.fixture;
  c.backend = result.actual;
  c.driver_version = result.actual_driver;
  c.state = result.state.is_object() ? result.state : json::object();
  c.tags = result.tags;
  return c;
}

bool covers(const Expectation& e, const PairContext& pair) {
  if (!globMatches(e.fixture, pair.fixture) || !backendMatches(e.backend, pair.backend))
    return false;
  if (!e.driver_version.empty() && !globMatches(e.driver_version, pair.driver_version))
    return false;
  for (const auto& [key, value] : e.state) {
    const auto it = pair.state.find(key);
    if (it == pair.state.end() || stateValue(*it) != value) return false;
  }
  for (const std::string& tag : e.tags)
    if (std::find(pair.tags.begin(), pair.tags.end(), tag) == pair.tags.end()) return false;
  return true;
}

std::vector<const Expectation*> expectationsFor(const Expectations& x, const PairContext& pair,
                                                const std::string& cls) {
  std::vector<const Expectation*> out;
  for (const Expectation& e : x.entries)
    if (e.cls == cls && covers(e, pair)) out.push_back(&e);
  return out;
}

std::vector<KnownFailure> knownFailuresOf(const Expectations& x, const PairResult& r) {
  if (r.status != Status::Fail) return {};
  const PairContext pair = contextOf(r);
  std::vector<KnownFailure> known;
  const std::pair<const char*, Status> classes[] = {{"visibility", r.visibility.status},
                                                    {"depth", r.depth.status},
                                                    {"shading", r.shading.status}};
  for (const auto& [cls, status] : classes) {
    if (status != Status::Fail) continue;
    const auto entries = expectationsFor(x, pair, cls);
    if (entries.empty()) return {};
    for (const Expectation* e : entries) known.push_back({e->id, e->cls, e->reason});
  }
  return known;
}

void applyExpectations(const Expectations& x, Report& report) {
  for (PairResult& r : report.results) r.known = knownFailuresOf(x, r);
}

}  // namespace rc
