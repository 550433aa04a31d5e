// Helpers for the debugging-tool tests: running the rastercheck binary, scratch folders,
// catalog paths, and the checks every `explain --json` document must pass (its terms add
// up to the colour, its final entry is what frame.exr holds).
#pragma once

#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "fixtures/frame.h"
#include "fixtures/frame_io.h"
#include "tests/support/command.h"

namespace rc::debugtest {

namespace fs = std::filesystem;
using nlohmann::json;

using Result = rc::test::CommandResult;  // stdout in `out`, stderr in `err`

// Runs the rastercheck binary with `args` (a shell word list), capturing stdout and
// stderr separately. `env` is prepended to the command ("VAR=value").
inline Result run(const std::string& args, const std::string& env = "") {
  return rc::test::runShell(env + " " RC_EXE " " + args, /*separate_err=*/true);
}

inline fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("rc_dbg_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

inline std::string catalog(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/fixtures/scenes/" + rel;
}
inline std::string testData(const std::string& rel) {
  return std::string(RC_SOURCE_DIR) + "/tests/debug/data/" + rel;
}

inline int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

inline glm::dvec3 v3(const json& a) {
  return glm::dvec3(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>());
}
inline glm::dvec4 v4(const json& a) {
  return glm::dvec4(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>(),
                    a.at(3).get<double>());
}

// The reference's frame of a fixture, through the real `render` command.
inline Frame renderRef(const std::string& fixture, const fs::path& dir,
                       const std::string& spec = "ref") {
  const Result r = run("render " + fixture + " --backend " + spec + " --out " + dir.string());
  EXPECT_EQ(r.code, 0) << r.err;
  return readFrameDir(dir);
}

// The colour format's conversion of one channel (DESIGN.md: rgba8 rounds to nearest
// after clamping; rgba32f keeps floats), as frame.exr holds it. Not inlined: GCC 12.2 at
// -O3 (SLP vectorizer) dropped the double -> float -> double round trip of the rgba32f
// branch for channels 0 and 1 when this was inlined into checkExplain's replay loop
// (correct at -O0..-O2 and with -fno-tree-slp-vectorize).
__attribute__((noinline)) inline float store(double c, const std::string& format) {
  if (format == "rgba32f") return static_cast<float>(c);
  const double clamped = c > 0.0 ? (c < 1.0 ? c : 1.0) : 0.0;
  return static_cast<float>(std::nearbyint(clamped * 255.0) / 255.0);
}

// A stored channel read back for blending: rgba8 values are exactly q / 255.
inline double load(double stored, const std::string& format) {
  return format == "rgba32f" ? stored : std::nearbyint(stored * 255.0) / 255.0;
}

// Every check an explain document must pass against the reference frame of its
// fixture; `where` labels failures.
inline void checkExplain(const json& doc, const Frame& frame, const std::string& where) {
  SCOPED_TRACE(where);
  const int x = doc["pixel"]["image"][0].get<int>();
  const int y = doc["pixel"]["image"][1].get<int>();
  EXPECT_EQ(doc["pixel"]["window"][0].get<int>(), x);
  EXPECT_EQ(doc["pixel"]["window"][1].get<int>(), frame.height - 1 - y);
  const std::size_t i = frame.index(x, y);
  const std::string color_format = doc["reference"]["color_format"].get<std::string>();

  // final = frame.exr, exactly.
  const json& fin = doc["final"];
  EXPECT_EQ(fin["id"].get<std::uint32_t>(), frame.id[i]);
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(static_cast<float>(fin["color"][c].get<double>()), frame.color[4 * i + c]) << c;
  EXPECT_EQ(static_cast<float>(fin["depth"].get<double>()), frame.depth[i]);
  EXPECT_EQ(static_cast<float>(doc["edge_dist"].get<double>()), frame.edge_dist[i]);
  if (std::isinf(frame.depth_gap[i])) {
    EXPECT_TRUE(doc["depth_gap"].is_null());
  } else {
    EXPECT_EQ(static_cast<float>(doc["depth_gap"].get<double>()), frame.depth_gap[i]);
  }

  // Replay the colour and depth buffers through the fragments.
  glm::dvec4 buffer = v4(doc["clear"]["color"]);  // as read back for blending
  double depth = doc["clear"]["depth"].get<double>();
  std::string depth_source = "clear";
  json last_pass = nullptr;
  for (const json& f : doc["fragments"]) {
    SCOPED_TRACE("fragment " + f["index"].dump());
    const json& sh = f["shading"];
    const std::string model = sh["model"].get<std::string>();
    const glm::dvec3 tex = sh["texture"].is_null() ? glm::dvec3(1.0) : v3(sh["texture"]);
    glm::dvec3 ad = v3(sh["ambient"]);
    glm::dvec3 spec(0.0);
    for (const json& l : sh["lights"]) {
      ad += v3(l["diffuse"]);
      spec += v3(l["specular"]);
      EXPECT_EQ(l["factors"].size(), sh["points"].size());
    }
    const glm::dvec4 color = v4(sh["color"]);
    EXPECT_EQ(color.a, sh["opacity"].get<double>());
    if (model == "gouraud") {
      ASSERT_EQ(sh["points"].size(), 3u);
      glm::dvec3 pad(0.0);
      glm::dvec3 ps(0.0);
      const glm::dvec3 b = v3(f["barycentric"]);
      for (int k = 0; k < 3; ++k) {
        const json& p = sh["points"][k];
        EXPECT_EQ(p["weight"].get<double>(), b[k]);
        pad = k == 0 ? b[k] * v3(p["ambient_diffuse"]) : pad + b[k] * v3(p["ambient_diffuse"]);
        ps = k == 0 ? b[k] * v3(p["specular"]) : ps + b[k] * v3(p["specular"]);
      }
      const glm::dvec3 exact = pad * tex + ps;
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(exact[c], color[c]) << "channel " << c;
        EXPECT_NEAR(ad[c] * tex[c] + spec[c], color[c], 1e-12) << "channel " << c;
      }
    } else {
      ASSERT_EQ(sh["points"].size(), 1u);
      const glm::dvec3 sum = ad * tex + spec;
      const glm::dvec3 point_ad = v3(sh["points"][0]["ambient_diffuse"]);
      const glm::dvec3 point_spec = v3(sh["points"][0]["specular"]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(sum[c], color[c]) << "channel " << c;
        EXPECT_EQ(point_ad[c], ad[c]);
        EXPECT_EQ(point_spec[c], spec[c]);
      }
    }
    // Depth test.
    const json& t = f["depth_test"];
    EXPECT_EQ(t["against"].get<double>(), depth);
    EXPECT_EQ(t["against_source"].get<std::string>(), depth_source);
    const double stored = f["depth"]["stored"].get<double>();
    const bool pass = t["func"] == "always" || stored < depth;
    EXPECT_EQ(t["result"].get<std::string>(), pass ? "pass" : "fail");
    EXPECT_EQ(f["written"].get<bool>(), pass);
    if (f["depth"]["format"] == "d24") {
      EXPECT_NEAR(stored * 16777215.0, f["depth"]["steps"].get<double>(), 1e-6);
    }
    // Colour (plain arrays: element-wise replay, channel by channel).
    std::array<double, 4> expected_after{buffer.x, buffer.y, buffer.z, buffer.w};
    if (pass) {
      std::array<double, 4> result{color.x, color.y, color.z, color.w};
      if (f["draw"]["blend"].get<bool>()) {
        ASSERT_FALSE(f["blend"].is_null());
        std::array<double, 4> src = result;
        if (color_format == "rgba8") {
          for (double& v : src) v = v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
        }
        const double a = src[3];
        const glm::dvec4 blend_result = v4(f["blend"]["result"]);
        const glm::dvec4 blend_dst = v4(f["blend"]["dst"]);
        for (int c = 0; c < 4; ++c) {
          result[c] = src[c] * a + buffer[c] * (1.0 - a);
          EXPECT_EQ(blend_result[c], result[c]) << "blend channel " << c;
          EXPECT_EQ(blend_dst[c], buffer[c]) << "blend dst channel " << c;
        }
      } else {
        EXPECT_TRUE(f["blend"].is_null());
      }
      for (int c = 0; c < 4; ++c) expected_after[c] = store(result[c], color_format);
      if (f["depth_test"]["write"].get<bool>()) {
        depth = stored;
        depth_source = "fragment " + f["index"].dump();
      }
      last_pass = f["index"];
    }
    const glm::dvec4 after = v4(f["color_after"]);
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(after[c], expected_after[c]) << "color_after channel " << c;
      buffer[c] = load(after[c], color_format);  // what the next blend reads
    }
  }
  EXPECT_EQ(fin["fragment"], last_pass);
  for (int c = 0; c < 4; ++c)
    EXPECT_EQ(static_cast<float>(buffer[c]), frame.color[4 * i + c]) << "replayed channel " << c;
  if (doc["fragments"].empty()) {
    EXPECT_EQ(fin["id"], 0);
  }
}

// Key paths of a document in docs/explain.md's notation ("fragments[].depth.window",
// "backends.SPEC.id").
inline void collectKeys(const json& j, const std::string& path, std::set<std::string>& out) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const std::string k = path == "backends" ? "SPEC" : key;
      const std::string p = path.empty() ? k : path + "." + k;
      out.insert(p);
      collectKeys(value, p, out);
    }
  } else if (j.is_array()) {
    for (const json& e : j) collectKeys(e, path + "[]", out);
  }
}

// The first column of docs/explain.md's key table.
inline std::set<std::string> documentedKeys() {
  std::ifstream in(std::string(RC_SOURCE_DIR) + "/docs/explain.md");
  std::set<std::string> keys;
  const std::regex row(R"(^\| `([^`]+)` \|)");
  std::string line;
  std::smatch m;
  while (std::getline(in, line))
    if (std::regex_search(line, m, row)) keys.insert(m[1]);
  return keys;
}

}  // namespace rc::debugtest
