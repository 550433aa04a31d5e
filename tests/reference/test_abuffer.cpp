// ref:abuffer (ReferenceOptions::abuffer) against a brute-force per-pixel fragment list
// built here from analytic triangle coverage and plane depths, blended in closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "fixtures/multisample.h"
#include "reference/reference_renderer.h"
#include "tests/reference/test_scenes.h"

namespace rc {
namespace {

constexpr int kSize = 32;
constexpr double kD24 = 16777215.0;

// A transparent triangle of the test scene in window coordinates (windowScene: world x, y
// are GL window x, y; window depth = 1 - world z).
struct Tri {
  glm::dvec3 p[3];  // world positions
  glm::dvec3 color;
  double alpha;
};

// Interpenetrating tilted triangles in front of an opaque wall at world z 0.05 (window
// depth 0.95); every fragment is nearer than the wall.
std::vector<Tri> triangles() {
  return {
      {{{-8, -6, 0.2}, {44, -4, 0.8}, {-6, 44, 0.5}}, {1.0, 0.1, 0.1}, 0.5},
      {{{40, -8, 0.3}, {38, 42, 0.85}, {-10, 10, 0.6}}, {0.1, 1.0, 0.1}, 0.4},
      {{{2, 40, 0.25}, {-6, -10, 0.7}, {42, 20, 0.45}}, {0.1, 0.1, 1.0}, 0.6},
      {{{16, -12, 0.55}, {44, 36, 0.4}, {-12, 30, 0.52}}, {0.9, 0.9, 0.1}, 0.3},
  };
}
constexpr glm::dvec3 kWallColor{0.3, 0.3, 0.3};
constexpr double kWallZ = 0.05;

Scene abufferScene(const std::vector<Tri>& tris) {
  Scene s = test::windowScene(kSize, kSize);
  s.state.blend = Blend::Alpha;
  Material wall;
  wall.ambient = kWallColor;
  wall.diffuse = wall.specular = glm::dvec3(0.0);
  const std::size_t wall_mat = test::addMaterial(s, wall);
  test::addRect(s, -1, -1, kSize + 1, kSize + 1, static_cast<float>(kWallZ), wall_mat);  // ids 1, 2
  for (const Tri& t : tris) {
    Material m;
    m.ambient = t.color;
    m.diffuse = m.specular = glm::dvec3(0.0);
    m.opacity = t.alpha;
    const std::size_t mat = test::addMaterial(s, m);
    test::addTriangle(s, glm::vec3(t.p[0]), glm::vec3(t.p[1]), glm::vec3(t.p[2]), mat);
  }
  return s;
}

// Signed distance (px) of point q from the line a -> b, > 0 on the left.
double edgeDistance(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& q) {
  const glm::dvec2 d = b - a;
  return (d.x * (q.y - a.y) - d.y * (q.x - a.x)) / std::hypot(d.x, d.y);
}

struct Oracle {
  bool skip = false;       // a pixel centre too near an edge or a depth tie to be sure
  std::vector<int> order;  // triangle indices covering the centre, far to near
  std::vector<double> z;   // their window depths, same order
  glm::dvec3 color{0.0};
};

// The fragment list at window point c (a pixel centre, or a sample position).
Oracle oracleAtPoint(const std::vector<Tri>& tris, const glm::dvec2& c) {
  Oracle o;
  std::vector<std::pair<double, int>> frags;
  for (int k = 0; k < static_cast<int>(tris.size()); ++k) {
    const Tri& t = tris[k];
    const glm::dvec2 a(t.p[0]), b(t.p[1]), d(t.p[2]);
    const double area = (b.x - a.x) * (d.y - a.y) - (d.x - a.x) * (b.y - a.y);
    const double sign = area > 0 ? 1.0 : -1.0;
    const double e0 = sign * edgeDistance(a, b, c);
    const double e1 = sign * edgeDistance(b, d, c);
    const double e2 = sign * edgeDistance(d, a, c);
    if (std::min({std::fabs(e0), std::fabs(e1), std::fabs(e2)}) < 0.01) o.skip = true;
    if (e0 <= 0 || e1 <= 0 || e2 <= 0) continue;
    // Barycentrics in the window plane (orthographic: depth is linear in x, y).
    const double l1 = ((c.x - a.x) * (d.y - a.y) - (d.x - a.x) * (c.y - a.y)) / area;
    const double l2 = ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y)) / area;
    const double world_z = (1 - l1 - l2) * t.p[0].z + l1 * t.p[1].z + l2 * t.p[2].z;
    frags.emplace_back(1.0 - world_z, k);
  }
  std::sort(frags.begin(), frags.end(), [](auto& x, auto& y) { return x.first > y.first; });
  for (std::size_t i = 0; i + 1 < frags.size(); ++i)
    if (frags[i].first - frags[i + 1].first < 1e-6) o.skip = true;
  // Closed form of blending far to near over the wall:
  // C = wall * prod(1 - a_i) + sum_i a_i c_i prod_{j nearer than i} (1 - a_j).
  glm::dvec3 color = kWallColor;
  double through = 1.0;
  for (const auto& f : frags) through *= 1.0 - tris[f.second].alpha;
  color *= through;
  for (std::size_t i = 0; i < frags.size(); ++i) {
    double over = 1.0;
    for (std::size_t j = i + 1; j < frags.size(); ++j) over *= 1.0 - tris[frags[j].second].alpha;
    color += tris[frags[i].second].alpha * tris[frags[i].second].color * over;
  }
  for (const auto& f : frags) {
    o.order.push_back(f.second);
    o.z.push_back(f.first);
  }
  o.color = color;
  return o;
}

Oracle oracleAt(const std::vector<Tri>& tris, int px, int gl_y) {
  return oracleAtPoint(tris, glm::dvec2(px + 0.5, gl_y + 0.5));
}

// Whether the sorted pass draws triangle `far` after the nearer `near`: the mean view
// depth order of the pass (1 - z here), ties in file order.
std::vector<int> drawPositions(const std::vector<Tri>& tris) {
  std::vector<int> draw(tris.size());
  for (std::size_t k = 0; k < tris.size(); ++k) draw[k] = static_cast<int>(k);
  auto mean_depth = [&](int k) {
    return 1.0 - (tris[k].p[0].z + tris[k].p[1].z + tris[k].p[2].z) / 3.0;
  };
  std::stable_sort(draw.begin(), draw.end(),
                   [&](int a, int b) { return mean_depth(a) > mean_depth(b); });
  std::vector<int> pos(tris.size());
  for (std::size_t k = 0; k < draw.size(); ++k) pos[draw[k]] = static_cast<int>(k);
  return pos;
}

TEST(ABuffer, MatchesBruteForceFragmentLists) {
  const std::vector<Tri> tris = triangles();
  const Scene scene = abufferScene(tris);
  ReferenceOptions opts;
  opts.abuffer = true;
  const Frame f = renderReference(scene, opts);
  // The far-to-near order of the triangle pass, by mean view depth (1 - z here).
  const std::vector<int> draw_pos = drawPositions(tris);

  int checked = 0, multi = 0;
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> oracle_pairs;  // (near, far) ids
  for (int gl_y = 0; gl_y < kSize; ++gl_y) {
    for (int x = 0; x < kSize; ++x) {
      const Oracle o = oracleAt(tris, x, gl_y);
      if (o.skip) continue;
      ++checked;
      const std::size_t i = f.index(x, kSize - 1 - gl_y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(f.color[4 * i + c], o.color[c], 2e-6) << "pixel " << x << "," << gl_y;
      // The id is the nearest fragment's (ids: wall 1-2, triangle k is 3 + k).
      const std::uint32_t want = o.order.empty() ? 1u : 3u + o.order.back();
      if (o.order.empty()) {
        EXPECT_LE(f.id[i], 2u);
      } else {
        EXPECT_EQ(f.id[i], want) << "pixel " << x << "," << gl_y;
      }
      EXPECT_EQ(f.blend_count[i], static_cast<float>(o.order.size()));
      if (o.order.size() >= 2) {
        ++multi;
        double min_gap = 1e9;
        for (std::size_t k = 0; k + 1 < o.z.size(); ++k)
          min_gap = std::min(min_gap, o.z[k] - o.z[k + 1]);
        // The other gaps that count: each fragment's test against the wall, and what
        // decided the wall under them (its distance from the clear depth, 0.05).
        double want_gap = std::min(min_gap, kWallZ);
        for (double z : o.z) want_gap = std::min(want_gap, (1.0 - kWallZ) - z);
        EXPECT_NEAR(f.blend_gap[i], want_gap * kD24, 2.0) << "pixel " << x << "," << gl_y;
        const double last_gap = o.z[o.z.size() - 2] - o.z.back();
        EXPECT_LE(f.depth_gap[i], last_gap * kD24 + 2.0);
        for (std::size_t a = 0; a < o.order.size(); ++a)
          for (std::size_t b = a + 1; b < o.order.size(); ++b)
            if (draw_pos[o.order[a]] > draw_pos[o.order[b]])
              ++oracle_pairs[{3u + o.order[b], 3u + o.order[a]}];
      }
    }
  }
  EXPECT_GT(checked, kSize * kSize * 3 / 4);
  EXPECT_GT(multi, 200);
  // Every out-of-order pair the oracle found is reported, with at least its pixels.
  ASSERT_TRUE(f.meta.contains("abuffer"));
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint64_t> reported;
  for (const auto& p : f.meta["abuffer"]["out_of_order"])
    reported[{p["near"].get<std::uint32_t>(), p["far"].get<std::uint32_t>()}] =
        p["pixels"].get<std::uint64_t>();
  EXPECT_FALSE(oracle_pairs.empty());
  for (const auto& [pair, n] : oracle_pairs) {
    ASSERT_TRUE(reported.count(pair)) << pair.first << " over " << pair.second;
    EXPECT_GE(reported[pair], static_cast<std::uint64_t>(n));
  }
}

// Where the draw order of the sorted pass is the depth order, the plain reference blends
// the same fragments in the same order: the colours are bit for bit equal; elsewhere
// (some pixel here) they differ.
TEST(ABuffer, EqualsThePlainReferenceWhereTheOrdersAgree) {
  const std::vector<Tri> tris = triangles();
  Scene scene = abufferScene(tris);
  scene.state.color_format = ColorFormat::RGBA8;  // with 8-bit rounding after every blend
  ReferenceOptions opts;
  const Frame plain = renderReference(scene, opts);
  opts.abuffer = true;
  const Frame exact = renderReference(scene, opts);
  std::set<std::size_t> unsorted;
  const int n_unsorted = exact.meta["abuffer"]["unsorted_pixels"].get<int>();
  int differ = 0;
  for (std::size_t i = 0; i < plain.pixelCount(); ++i) {
    bool same = true;
    for (int c = 0; c < 4; ++c) same = same && plain.color[4 * i + c] == exact.color[4 * i + c];
    differ += !same || plain.id[i] != exact.id[i];
  }
  EXPECT_GT(n_unsorted, 0);
  EXPECT_GT(differ, 0);
  EXPECT_LE(differ, n_unsorted);  // only pixels the draw order gets wrong may differ
  // The opaque depth and everything drawn without blending are unchanged.
  EXPECT_EQ(plain.depth, exact.depth);
}

TEST(ABuffer, DeterministicAndTracedListMatchesTheFrame) {
  const Scene scene = abufferScene(triangles());
  ReferenceOptions opts;
  opts.abuffer = true;
  const Frame a = renderReference(scene, opts);
  const Frame b = renderReference(scene, opts);
  EXPECT_EQ(test::frameBytes(a), test::frameBytes(b));
  for (int y : {3, 16, 27})
    for (int x : {4, 15, 26}) {
      const std::vector<SortedFragment> list = abufferPixel(scene, opts, x, y);
      const std::size_t i = a.index(x, y);
      EXPECT_EQ(static_cast<float>(list.size()), a.blend_count[i]);
      if (list.empty()) continue;
      EXPECT_EQ(list.back().primitive, a.id[i]);
      for (std::size_t k = 0; k + 1 < list.size(); ++k)
        EXPECT_GE(list[k].window_z, list[k + 1].window_z);
      for (int c = 0; c < 4; ++c)
        EXPECT_EQ(static_cast<float>(list.back().color_after[c]), a.color[4 * i + c]);
    }
}

// Multisampled (4x, standard positions): every sample keeps and blends its own lists, the
// resolve averages them, and frame.json "abuffer" joins the samples: a pixel counts as
// blended / unsorted (and towards a pair) when any of its samples does, kept_fragments
// sums the samples. Checked against the brute-force lists at each sample position.
TEST(ABuffer, MultisampledListsAreJoinedOverTheSamples) {
  const std::vector<Tri> tris = triangles();
  Scene scene = abufferScene(tris);
  scene.state.samples = 4;
  ReferenceOptions opts;
  opts.abuffer = true;
  const Frame f = renderReference(scene, opts);
  ASSERT_EQ(f.samples, 4);
  ASSERT_TRUE(f.meta.contains("abuffer"));
  const nlohmann::json& meta = f.meta["abuffer"];
  const std::vector<glm::dvec2> pos = standardSamplePositions(4);
  const std::vector<int> draw_pos = drawPositions(tris);

  std::uint64_t blended = 0, unsorted = 0, kept = 0, unsure = 0, mixed = 0, partly_unsorted = 0;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint64_t> oracle_pairs;
  for (int gl_y = 0; gl_y < kSize; ++gl_y) {
    for (int x = 0; x < kSize; ++x) {
      bool skip = false, any_blended = false, any_unsorted = false;
      int samples_unsorted = 0;
      std::set<std::vector<int>> lists;
      glm::dvec3 mean(0.0);
      std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
      for (const glm::dvec2& p : pos) {
        const Oracle o = oracleAtPoint(tris, glm::dvec2(x, gl_y) + p);
        skip = skip || o.skip;
        mean += o.color / 4.0;
        kept += o.order.size();
        any_blended = any_blended || !o.order.empty();
        lists.insert(o.order);
        bool sample_unsorted = false;
        for (std::size_t a = 0; a < o.order.size(); ++a)
          for (std::size_t b = a + 1; b < o.order.size(); ++b)
            if (draw_pos[o.order[a]] > draw_pos[o.order[b]]) {
              sample_unsorted = true;
              pairs.insert({3u + o.order[b], 3u + o.order[a]});
            }
        any_unsorted = any_unsorted || sample_unsorted;
        samples_unsorted += sample_unsorted;
      }
      if (skip) {
        ++unsure;
        continue;
      }
      blended += any_blended;
      unsorted += any_unsorted;
      mixed += lists.size() > 1;
      partly_unsorted += samples_unsorted > 0 && samples_unsorted < 4;
      for (const auto& q : pairs) ++oracle_pairs[q];
      const std::size_t i = f.index(x, kSize - 1 - gl_y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(f.color[4 * i + c], mean[c], 4e-6) << "pixel " << x << "," << gl_y;
    }
  }
  // Pixels whose samples lie on an edge or a depth tie may go either way.
  EXPECT_LT(unsure, static_cast<std::uint64_t>(kSize * kSize / 8));
  // Pixels whose samples hold different lists, and pixels only some samples of which are
  // out of order: where joining the samples matters.
  EXPECT_GT(mixed, 10u);
  EXPECT_GT(partly_unsorted, 0u);
  const auto got_blended = meta["blended_pixels"].get<std::uint64_t>();
  const auto got_unsorted = meta["unsorted_pixels"].get<std::uint64_t>();
  EXPECT_GE(got_blended, blended);
  EXPECT_LE(got_blended, blended + unsure);
  EXPECT_GT(unsorted, 0u);
  EXPECT_GE(got_unsorted, unsorted);
  EXPECT_LE(got_unsorted, unsorted + unsure);
  // Fragments: every sample's, give or take the unsure pixels' (at most 4 x 4 each).
  const auto got_kept = meta["kept_fragments"].get<std::uint64_t>();
  EXPECT_NEAR(static_cast<double>(got_kept), static_cast<double>(kept),
              16.0 * static_cast<double>(unsure));
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint64_t> reported;
  for (const auto& p : meta["out_of_order"])
    reported[{p["near"].get<std::uint32_t>(), p["far"].get<std::uint32_t>()}] =
        p["pixels"].get<std::uint64_t>();
  EXPECT_EQ(meta["out_of_order_pairs"].get<std::size_t>(), reported.size());
  for (const auto& [pair, n] : oracle_pairs) {
    ASSERT_TRUE(reported.count(pair)) << pair.first << " over " << pair.second;
    EXPECT_GE(reported[pair], n);
    EXPECT_LE(reported[pair], n + unsure);
  }
}

}  // namespace
}  // namespace rc
