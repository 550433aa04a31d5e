// Variant detection probes and their analysis: see variants.h and docs/debugging.md.
#include "debug/variants.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include <fmt/format.h>

#include "fixtures/errors.h"
#include "reference/reference_renderer.h"

namespace rc::variants {
namespace {

constexpr double kD24Steps = 16777215.0;  // 2^24 - 1

// The shared probe set-up: an orthographic camera whose view volume is the image, so
// world (x, y) is GL window (x, y), and view depth D in [1, 3] maps to window z
// (D - 1) / 2 (near 1, far 3: ndc z = D - 2, exact in float for D in [1, 3]).
Scene probeScene(const std::string& name, const std::string& description, int width, int height) {
  Scene s;
  s.name = "probe/" + name;
  s.description = description;
  s.tags = {"probe"};
  s.width = width;
  s.height = height;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = glm::dvec3(0.0);
  s.camera.target = glm::dvec3(0.0, 0.0, -1.0);
  s.camera.up = glm::dvec3(0.0, 1.0, 0.0);
  s.camera.bounds = glm::dvec4(0.0, width, 0.0, height);
  s.camera.near = 1.0;
  s.camera.far = 3.0;
  s.ambient_light = glm::dvec3(1.0);
  Material m;
  m.name = "probe";
  m.ambient = glm::dvec3(1.0);
  m.diffuse = glm::dvec3(0.0);
  s.materials.push_back(m);
  s.state.shading = Shading::Flat;
  return s;
}

// One object per triangle group, facing the camera (+z normals).
void addObject(Scene& scene, const std::string& name, const std::vector<glm::vec3>& positions,
               const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  Object o;
  o.name = name;
  o.mesh.positions = positions;
  o.mesh.normals.assign(positions.size(), glm::vec3(0.0f, 0.0f, 1.0f));
  o.mesh.triangles = triangles;
  scene.objects.push_back(std::move(o));
}

void checkSize(const Frame& f, int width, int height, const char* probe) {
  if (f.width != width || f.height != height || f.id.size() != f.pixelCount() ||
      f.depth.size() != f.pixelCount())
    throw InputError(fmt::format("{} probe: frame is {}x{}, expected {}x{}", probe, f.width,
                                 f.height, width, height));
}

}  // namespace

// ---- (a) subpixel -----------------------------------------------------------------------

Scene subpixelProbe(std::uint32_t seed) {
  constexpr int kCells = 8;
  constexpr int kCell = 12;
  constexpr int kLeg = 9;
  Scene s = probeScene("subpixel",
                       "Variant probe: right triangles whose legs run along pixel centres, "
                       "vertices offset by random +-u*2^-k px (k = 1..13)",
                       kCells * kCell, kCells * kCell);
  // Raw mt19937 words (the distributions' algorithms differ between standard libraries).
  std::mt19937 rng(seed);
  auto unit = [&] { return static_cast<double>(rng() >> 8) * 0x1p-24; };
  auto offset = [&] {
    const int k = 1 + static_cast<int>(rng() % 12);
    const double u = 0.3 + 0.7 * unit();
    const auto m = static_cast<std::int64_t>(std::lround(std::ldexp(u, 16 - k))) | 1;
    return ((rng() & 1u) ? 1.0 : -1.0) * static_cast<double>(m) * 0x1p-16;
  };
  for (int cy = 0; cy < kCells; ++cy) {
    for (int cx = 0; cx < kCells; ++cx) {
      const int sx = (rng() & 1u) ? 1 : -1;
      const int sy = (rng() & 1u) ? 1 : -1;
      const int ox = cx * kCell + 1 + (sx > 0 ? 0 : kLeg);
      const int oy = cy * kCell + 1 + (sy > 0 ? 0 : kLeg);
      auto vertex = [&](int px, int py) {
        const double x = px + 0.5 + offset();
        const double y = py + 0.5 + offset();
        return glm::vec3(static_cast<float>(x), static_cast<float>(y), -2.0f);
      };
      const glm::vec3 a = vertex(ox, oy);
      const glm::vec3 b = vertex(ox, oy + sy * kLeg);
      const glm::vec3 c = vertex(ox + sx * kLeg, oy);
      addObject(s, fmt::format("t{}_{}", cx, cy), {a, b, c}, {{0, 1, 2}});
    }
  }
  return s;
}

SubpixelResult analyseSubpixel(const Frame& driver, const std::map<int, Frame>& reference) {
  SubpixelResult r;
  auto integer = [&](const char* key) {
    const auto it = driver.meta.find(key);
    return it != driver.meta.end() && it->is_number_integer() ? it->get<int>() : -1;
  };
  r.band = integer("subpixel_bits");
  r.queried = driver.meta.contains("gl_subpixel_bits") ? integer("gl_subpixel_bits") : r.band;
  if (const auto it = driver.meta.find("subpixel_bits_source");
      it != driver.meta.end() && it->is_string())
    r.band_source = it->get<std::string>();
  for (const auto& [bits, ref] : reference) {
    checkSize(ref, driver.width, driver.height, "subpixel");
    checkSize(driver, ref.width, ref.height, "subpixel");
    std::uint64_t n = 0;
    for (std::size_t i = 0; i < driver.id.size(); ++i) n += driver.id[i] != ref.id[i];
    r.mismatches[bits] = n;
    if (r.best < 0 || n < r.best_mismatches) {
      r.best = bits;
      r.best_mismatches = n;
    }
  }
  r.exact = r.best >= 0 && r.best_mismatches == 0;
  const auto q = r.mismatches.find(r.queried);
  r.confirmed = q != r.mismatches.end() && q->second == 0;
  const auto b = r.mismatches.find(r.band);
  r.band_confirmed = b != r.mismatches.end() && b->second == 0;
  if (r.exact && r.queried >= 0 && !r.confirmed) {
    r.finding = fmt::format("GL_SUBPIXEL_BITS says {} but the driver rasterizes like {} bits{}",
                            r.queried, r.best, r.best == kMaxCandidateBits ? " or finer" : "");
  } else if (!r.exact && r.best >= 0 && r.queried >= 0) {
    r.finding = fmt::format(
        "GL_SUBPIXEL_BITS says {} but no fixed grid of {}..{} bits reproduces the driver's "
        "coverage (closest: {} bits)",
        r.queried, kMinCandidateBits, kMaxCandidateBits, r.best);
  }
  return r;
}

// ---- (b) tie-break ----------------------------------------------------------------------

const char* toString(EdgeSide side) {
  switch (side) {
    case EdgeSide::Left:
      return "left";
    case EdgeSide::Right:
      return "right";
    case EdgeSide::Bottom:
      return "bottom";
    case EdgeSide::Top:
      return "top";
    case EdgeSide::BottomLeft:
      return "bottom-left";
    case EdgeSide::BottomRight:
      return "bottom-right";
    case EdgeSide::TopLeft:
      return "top-left";
    case EdgeSide::TopRight:
      return "top-right";
  }
  return "?";
}

bool referenceIncludes(EdgeSide side) {
  // nx > 0: Left, BottomLeft, TopLeft; nx == 0 and ny > 0: Bottom.
  return side == EdgeSide::Left || side == EdgeSide::BottomLeft || side == EdgeSide::TopLeft ||
         side == EdgeSide::Bottom;
}

namespace {

EdgeSide sideOf(int nx, int ny) {
  if (nx == 0) return ny > 0 ? EdgeSide::Bottom : EdgeSide::Top;
  if (ny == 0) return nx > 0 ? EdgeSide::Left : EdgeSide::Right;
  if (nx > 0) return ny > 0 ? EdgeSide::BottomLeft : EdgeSide::TopLeft;
  return ny > 0 ? EdgeSide::BottomRight : EdgeSide::TopRight;
}

}  // namespace

namespace {

int cross2(glm::ivec2 a, glm::ivec2 b, glm::ivec2 c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// Adds one triangle (vertices = pixel indices; their centres are the window positions) and
// the centres strictly inside its edges: lattice points P + k * (d / g), 0 < k < g.
std::uint32_t addCentredTriangle(TieBreakProbe& probe, const std::string& name,
                                 const glm::ivec2 (&v)[3]) {
  const bool ccw = cross2(v[0], v[1], v[2]) > 0;
  const auto id = static_cast<std::uint32_t>(probe.scene.objects.size()) + 1;
  std::vector<glm::vec3> positions;
  for (const glm::ivec2& p : v)
    positions.emplace_back(static_cast<float>(p.x) + 0.5f, static_cast<float>(p.y) + 0.5f, -2.0f);
  addObject(probe.scene, name, positions, {{0, 1, 2}});
  for (int e = 0; e < 3; ++e) {
    const glm::ivec2 p = v[e];
    const glm::ivec2 d = v[(e + 1) % 3] - p;
    const int g = std::gcd(std::abs(d.x), std::abs(d.y));
    // The interior is to the left of the edge direction when counter-clockwise.
    const int nx = ccw ? -d.y : d.y;
    const int ny = ccw ? d.x : -d.x;
    for (int k = 1; k < g; ++k) {
      const glm::ivec2 c = p + k * (d / g);
      probe.centres.push_back({c.x, probe.scene.height - 1 - c.y, id, sideOf(nx, ny)});
    }
  }
  return id;
}

}  // namespace

TieBreakProbe tieBreakProbe() {
  constexpr int kCell = 8;
  TieBreakProbe probe;
  probe.scene = probeScene("tie_break",
                           "Variant probe: triangles with every vertex on a pixel centre, edges "
                           "through centres in every orientation and winding, alone and shared",
                           8 * kCell, 4 * kCell);
  int cell = 0;
  auto origin = [&] {
    const glm::ivec2 o((cell % 8) * kCell + 1, (cell / 8) * kCell + 1);
    ++cell;
    return o;
  };
  // Isolated right triangles: four corner orientations x both windings x two sizes.
  enum Corner { BL, BR, TL, TR };
  for (int leg : {5, 6}) {
    for (Corner corner : {BL, BR, TL, TR}) {
      for (bool ccw : {true, false}) {
        const glm::ivec2 o = origin();
        const int x = o.x;
        const int y = o.y;
        // The right angle's pixel first, then its two neighbours along the legs.
        glm::ivec2 v[3];
        switch (corner) {
          case BL:
            v[0] = {x, y}, v[1] = {x + leg, y}, v[2] = {x, y + leg};
            break;
          case BR:
            v[0] = {x + leg, y}, v[1] = {x + leg, y + leg}, v[2] = {x, y};
            break;
          case TL:
            v[0] = {x, y + leg}, v[1] = {x, y}, v[2] = {x + leg, y + leg};
            break;
          case TR:
            v[0] = {x + leg, y + leg}, v[1] = {x, y + leg}, v[2] = {x + leg, y};
            break;
        }
        if ((cross2(v[0], v[1], v[2]) > 0) != ccw) std::swap(v[1], v[2]);
        addCentredTriangle(probe, fmt::format("{}{}_{}", "ABCD"[corner], leg, ccw ? "ccw" : "cw"),
                           v);
      }
    }
  }
  // Pairs sharing an edge through centres (diagonal both ways, vertical, horizontal), in
  // both windings: each centre on the shared edge must go to exactly one of the two.
  for (bool ccw : {true, false}) {
    for (int shape = 0; shape < 4; ++shape) {
      const glm::ivec2 o = origin();
      glm::ivec2 a[3];
      glm::ivec2 b[3];
      glm::ivec2 s0;
      glm::ivec2 s1;
      switch (shape) {
        case 0:  // square split along "/"
          s0 = o, s1 = o + glm::ivec2(5, 5);
          a[0] = s0, a[1] = o + glm::ivec2(5, 0), a[2] = s1;
          b[0] = s0, b[1] = s1, b[2] = o + glm::ivec2(0, 5);
          break;
        case 1:  // square split along "\"
          s0 = o + glm::ivec2(5, 0), s1 = o + glm::ivec2(0, 5);
          a[0] = o, a[1] = s0, a[2] = s1;
          b[0] = s0, b[1] = o + glm::ivec2(5, 5), b[2] = s1;
          break;
        case 2:  // a vertical shared edge
          s0 = o + glm::ivec2(3, 0), s1 = o + glm::ivec2(3, 6);
          a[0] = s0, a[1] = s1, a[2] = o + glm::ivec2(0, 3);
          b[0] = s0, b[1] = o + glm::ivec2(6, 3), b[2] = s1;
          break;
        default:  // a horizontal shared edge
          s0 = o + glm::ivec2(0, 3), s1 = o + glm::ivec2(6, 3);
          a[0] = s0, a[1] = s1, a[2] = o + glm::ivec2(3, 6);
          b[0] = s0, b[1] = o + glm::ivec2(3, 0), b[2] = s1;
          break;
      }
      for (glm::ivec2* t : {a, b})
        if ((cross2(t[0], t[1], t[2]) > 0) != ccw) std::swap(t[1], t[2]);
      const std::uint32_t ia =
          addCentredTriangle(probe, fmt::format("pair{}a_{}", shape, ccw ? "ccw" : "cw"), a);
      const std::uint32_t ib =
          addCentredTriangle(probe, fmt::format("pair{}b_{}", shape, ccw ? "ccw" : "cw"), b);
      const glm::ivec2 d = s1 - s0;
      const int g = std::gcd(std::abs(d.x), std::abs(d.y));
      for (int k = 1; k < g; ++k) {
        const glm::ivec2 c = s0 + k * (d / g);
        probe.shared.push_back({c.x, probe.scene.height - 1 - c.y, ia, ib});
      }
    }
  }
  return probe;
}

TieBreakResult analyseTieBreak(const TieBreakProbe& probe, const Frame& driver) {
  checkSize(driver, probe.scene.width, probe.scene.height, "tie-break");
  TieBreakResult r;
  for (const EdgeCentre& c : probe.centres) {
    const bool included = driver.id[driver.index(c.x, c.y)] == c.primitive;
    TieBreakResult::Side& s = r.sides[c.side];
    s.included += included ? 1 : 0;
    ++s.total;
    if (included != referenceIncludes(c.side)) ++r.disagreements;
  }
  for (const SharedCentre& c : probe.shared) {
    const std::uint32_t id = driver.id[driver.index(c.x, c.y)];
    ++r.shared_centres;
    if (id != c.a && id != c.b) ++r.shared_gaps;
  }
  std::vector<std::string> included;
  std::vector<std::string> mixed;
  for (const auto& [side, s] : r.sides) {
    if (s.included != 0 && s.included != s.total) {
      r.consistent = false;
      mixed.push_back(fmt::format("{} {}/{}", toString(side), s.included, s.total));
    }
    const bool axis = side == EdgeSide::Left || side == EdgeSide::Right ||
                      side == EdgeSide::Bottom || side == EdgeSide::Top;
    if (axis && s.included == s.total && s.total > 0) included.emplace_back(toString(side));
  }
  r.rule = included.empty() ? "none" : fmt::format("{}", fmt::join(included, "+"));
  if (!mixed.empty()) r.rule += fmt::format(" (mixed: {})", fmt::join(mixed, ", "));
  r.matches_reference = r.disagreements == 0 && !probe.centres.empty();
  return r;
}

// ---- (c) depth rounding -----------------------------------------------------------------

DepthProbe depthProbe() {
  constexpr int kSize = 32;
  constexpr int kSquare = 4;
  constexpr int kPerRow = kSize / kSquare;
  DepthProbe probe;
  probe.scene = probeScene("depth_rounding",
                           "Variant probe: screen-parallel squares at window z = (2j+1)/128, "
                           "fractions of a d24 step from 127/128 down to 1/128",
                           kSize, kSize);
  probe.scene.state.depth_format = DepthFormat::D24;
  for (int j = 0; j < kPerRow * kPerRow; ++j) {
    const double z = (2.0 * j + 1.0) / 128.0;
    const auto view_depth = static_cast<float>(-(1.0 + 2.0 * z));  // exact: 8 bits
    const int x0 = (j % kPerRow) * kSquare;
    const int y0 = (j / kPerRow) * kSquare;  // window y
    const auto fx0 = static_cast<float>(x0);
    const auto fy0 = static_cast<float>(y0);
    const float fx1 = fx0 + kSquare;
    const float fy1 = fy0 + kSquare;
    DepthSample s;
    s.x0 = x0;
    s.x1 = x0 + kSquare;
    s.y0 = kSize - y0 - kSquare;  // image rows
    s.y1 = kSize - y0;
    s.primitive = static_cast<std::uint32_t>(2 * j + 1);
    s.window_z = z;
    probe.samples.push_back(s);
    addObject(probe.scene, fmt::format("z{}", j),
              {{fx0, fy0, view_depth},
               {fx1, fy0, view_depth},
               {fx1, fy1, view_depth},
               {fx0, fy1, view_depth}},
              {{0, 1, 2}, {0, 2, 3}});
  }
  return probe;
}

const char* toString(DepthRounding rule) {
  switch (rule) {
    case DepthRounding::Nearest:
      return "nearest";
    case DepthRounding::Truncate:
      return "truncate";
    case DepthRounding::NearestFloat32:
      return "nearest-float32";
    case DepthRounding::TruncateFloat32:
      return "truncate-float32";
  }
  return "?";
}

std::uint32_t convertDepth(double z, DepthRounding rule) {
  const double exact = z * kD24Steps;  // exact for the probe's 8-bit depths
  // A float32 multiply, as a shader or a SIMD conversion would do it.
  const float scaled = static_cast<float>(z) * static_cast<float>(kD24Steps);
  switch (rule) {
    case DepthRounding::Nearest:
      return static_cast<std::uint32_t>(std::nearbyint(exact));
    case DepthRounding::Truncate:
      return static_cast<std::uint32_t>(std::floor(exact));
    case DepthRounding::NearestFloat32:
      return static_cast<std::uint32_t>(std::nearbyint(static_cast<double>(scaled)));
    case DepthRounding::TruncateFloat32:
      return static_cast<std::uint32_t>(std::floor(static_cast<double>(scaled)));
  }
  return 0;
}

DepthRoundingResult analyseDepthRounding(const DepthProbe& probe, const Frame& driver) {
  checkSize(driver, probe.scene.width, probe.scene.height, "depth");
  DepthRoundingResult r;
  constexpr DepthRounding kRules[] = {DepthRounding::Nearest, DepthRounding::Truncate,
                                      DepthRounding::NearestFloat32,
                                      DepthRounding::TruncateFloat32};
  for (DepthRounding rule : kRules) r.agree[rule] = 0;
  for (const DepthSample& s : probe.samples) {
    ++r.samples;
    std::vector<std::uint32_t> stored;
    for (int y = s.y0; y < s.y1; ++y) {
      for (int x = s.x0; x < s.x1; ++x) {
        const std::size_t i = driver.index(x, y);
        if (driver.id[i] != s.primitive && driver.id[i] != s.primitive + 1) {
          ++r.uncovered;
          continue;
        }
        const double z = driver.depth[i];
        const double q = std::nearbyint(z * kD24Steps);
        if (!(q >= 0.0 && q <= kD24Steps) || static_cast<float>(q / kD24Steps) != driver.depth[i]) {
          r.readback_exact = false;
          continue;
        }
        stored.push_back(static_cast<std::uint32_t>(q));
      }
    }
    if (stored.empty()) continue;
    if (std::adjacent_find(stored.begin(), stored.end(), std::not_equal_to<>()) != stored.end())
      r.uniform = false;
    for (DepthRounding rule : kRules) {
      const std::uint32_t predicted = convertDepth(s.window_z, rule);
      if (std::all_of(stored.begin(), stored.end(),
                      [&](std::uint32_t q) { return q == predicted; }))
        ++r.agree[rule];
    }
  }
  r.rule = "none";
  for (DepthRounding rule : kRules) {
    if (r.samples > 0 && r.agree[rule] == r.samples && r.uncovered == 0 && r.readback_exact) {
      r.rule = toString(rule);
      break;
    }
  }
  r.matches_reference = r.rule == toString(DepthRounding::Nearest);
  return r;
}

// ---- report.json ------------------------------------------------------------------------

nlohmann::json toJson(const SubpixelResult& r) {
  nlohmann::json mismatches = nlohmann::json::object();
  for (const auto& [bits, n] : r.mismatches) mismatches[std::to_string(bits)] = n;
  auto bits = [](int n) { return n >= 0 ? nlohmann::json(n) : nlohmann::json(nullptr); };
  return {{"queried", bits(r.queried)},
          {"best", bits(r.best)},
          {"best_mismatches", r.best_mismatches},
          {"exact", r.exact},
          {"confirmed", r.confirmed},
          {"band", bits(r.band)},
          {"band_source",
           r.band_source.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.band_source)},
          {"band_confirmed", r.band_confirmed},
          {"finding", r.finding.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.finding)},
          {"mismatches", mismatches},
          {"summary", describeSubpixel(r)}};
}

nlohmann::json toJson(const TieBreakResult& r) {
  nlohmann::json sides = nlohmann::json::object();
  for (const auto& [side, s] : r.sides)
    sides[toString(side)] = {{"included", s.included},
                             {"total", s.total},
                             {"reference_includes", referenceIncludes(side)}};
  return {{"rule", r.rule},
          {"matches_reference", r.matches_reference},
          {"consistent", r.consistent},
          {"disagreements", r.disagreements},
          {"sides", sides},
          {"shared_edges", {{"centres", r.shared_centres}, {"gaps", r.shared_gaps}}},
          {"summary", describeTieBreak(r)}};
}

nlohmann::json toJson(const DepthRoundingResult& r) {
  nlohmann::json agree = nlohmann::json::object();
  for (const auto& [rule, n] : r.agree) agree[toString(rule)] = n;
  return {{"rule", r.rule},
          {"matches_reference", r.matches_reference},
          {"samples", r.samples},
          {"agree", agree},
          {"readback_exact", r.readback_exact},
          {"uniform", r.uniform},
          {"uncovered", r.uncovered},
          {"summary", describeDepthRounding(r)}};
}

namespace {

std::string describeSubpixelQueried(const SubpixelResult& r) {
  const std::string queried =
      r.queried >= 0 ? fmt::format("GL_SUBPIXEL_BITS {}", r.queried) : "GL_SUBPIXEL_BITS unknown";
  if (r.best < 0) return queried + ", not probed";
  if (r.confirmed)
    return fmt::format("{} bits ({}, confirmed: ref:subpixel={} reproduces the probe exactly)",
                       r.queried, queried, r.queried);
  const auto q = r.mismatches.find(r.queried);
  const std::string at_queried =
      q == r.mismatches.end()
          ? std::string()
          : fmt::format("; ref:subpixel={} differs in {} px", r.queried, q->second);
  if (r.exact && r.best == kMaxCandidateBits)
    return fmt::format(
        "{} bits or finer ({}, NOT confirmed{}; ref:subpixel={}, the finest "
        "grid tried, reproduces the probe exactly: no coarser snapping, e.g. float "
        "edge evaluation)",
        r.best, queried, at_queried, r.best);
  if (r.exact)
    return fmt::format(
        "{} bits ({}, NOT confirmed{}; ref:subpixel={} reproduces the probe exactly)", r.best,
        queried, at_queried, r.best);
  return fmt::format(
      "no fixed grid of {}..{} bits ({}, NOT confirmed{}; closest ref:subpixel={} still differs "
      "in {} px{})",
      kMinCandidateBits, kMaxCandidateBits, queried, at_queried, r.best, r.best_mismatches,
      r.best == kMaxCandidateBits ? ": finer than 2^-12 px, e.g. float edge evaluation" : "");
}

}  // namespace

std::string describeSubpixel(const SubpixelResult& r) {
  std::string s = describeSubpixelQueried(r);
  // Where the frames carry another precision than GL's answer, say which and whether the
  // probe bears it out: that is the band every comparison of this backend used.
  if (r.band >= 0 && r.band != r.queried && r.best >= 0) {
    s += fmt::format("; snap band: {} bits from {} ({})", r.band,
                     r.band_source.empty() ? std::string("frame.json") : r.band_source,
                     r.band_confirmed ? "confirmed by the probe" : "NOT confirmed by the probe");
  }
  return s;
}

std::string describeTieBreak(const TieBreakResult& r) {
  if (r.sides.empty()) return "not probed";
  std::string s = fmt::format("a centre exactly on an edge is covered on {} edges{}", r.rule,
                              r.consistent ? "" : " (inconsistently)");
  s += r.shared_gaps == 0
           ? fmt::format(", shared edges covered once ({} centres)", r.shared_centres)
           : fmt::format(", {} of {} centres on shared edges left uncovered", r.shared_gaps,
                         r.shared_centres);
  return s + (r.matches_reference
                  ? ": the reference's rule"
                  : fmt::format(": differs from the reference's left+bottom rule at {} of the "
                                "probe's centres",
                                r.disagreements));
}

std::string describeDepthRounding(const DepthRoundingResult& r) {
  if (r.samples == 0) return "not probed";
  std::string s =
      r.rule == "none"
          ? fmt::format(
                "no candidate rule predicts all {} samples "
                "(nearest {}, truncate {})",
                r.samples, r.agree.at(DepthRounding::Nearest), r.agree.at(DepthRounding::Truncate))
          : fmt::format("d24 conversion: {} (all {} samples)", r.rule, r.samples);
  s += r.matches_reference ? ", as the reference does" : ", unlike the reference (nearest)";
  if (!r.readback_exact) s += "; readback is not an exact multiple of 1/(2^24-1)";
  if (!r.uniform) s += "; depth varies inside a constant-depth square";
  if (r.uncovered) s += fmt::format("; {} probe pixels not drawn", r.uncovered);
  return s;
}

// ---- (d) lines and points -------------------------------------------------------------------

LineProbe lineProbe() {
  LineProbe probe;
  probe.scene = probeScene("lines", "Line rule, wide-line method and point squares", 128, 96);
  probe.scene.state.depth_test = false;
  std::uint32_t id = 1;
  auto add = [&](LineProbeItem::Kind kind, glm::dvec2 a, glm::dvec2 b, double size) {
    Object o;
    o.name = fmt::format("p{}", id);
    o.primitive = kind == LineProbeItem::Kind::Point ? PrimitiveKind::Points : PrimitiveKind::Lines;
    o.mesh.positions.emplace_back(static_cast<float>(a.x), static_cast<float>(a.y), -2.0f);
    if (kind != LineProbeItem::Kind::Point) {
      o.mesh.positions.emplace_back(static_cast<float>(b.x), static_cast<float>(b.y), -2.0f);
      o.mesh.lines = {{0, 1}};
      o.state.line_width = size;
    } else {
      o.state.point_size = size;
    }
    o.mesh.normals.assign(o.mesh.positions.size(), glm::vec3(0.0f, 0.0f, 1.0f));
    probe.scene.objects.push_back(std::move(o));
    probe.items.push_back({id++, kind, a, b, size});
  };
  // Sixteen one-pixel segments, 12 px long, in a 4 x 4 grid of 21 x 15 px cells (x < 84,
  // y < 60); ends at dyadic positions (exact in float32) off centres and diamond borders.
  auto dyadic = [](glm::dvec2 v) { return glm::round(v * 64.0) / 64.0; };
  for (int k = 0; k < 16; ++k) {
    const double angle = 2.0 * 3.14159265358979323846 * (k + 0.37) / 16.0;
    const glm::dvec2 c(10.5 + 21.0 * (k % 4) + 0.3125,
                       7.5 + 15.0 * static_cast<double>(k / 4) + 0.1875);
    const glm::dvec2 d(std::cos(angle), std::sin(angle));
    add(LineProbeItem::Kind::Thin, dyadic(c - 6.0 * d), dyadic(c + 6.0 * d), 1.0);
  }
  // Width 4 at 30 degrees (x-major) and 60 degrees (y-major), 30 px long, above them.
  add(LineProbeItem::Kind::Wide, dyadic({4.3125, 66.1875}), dyadic({30.3125, 81.1875}), 4.0);
  add(LineProbeItem::Kind::Wide, dyadic({44.3125, 64.1875}), dyadic({59.3125, 90.1875}), 4.0);
  // Points of size 3.5 and 5 at quarter-pixel positions, right of the segments.
  for (int k = 0; k < 8; ++k) {
    const glm::dvec2 c(92.0 + 9.0 * (k % 4) + 0.25 * k,
                       10.0 + 12.0 * static_cast<double>(k / 4) + 0.125);
    add(LineProbeItem::Kind::Point, c, c, k % 2 == 0 ? 3.5 : 5.0);
  }
  return probe;
}

LineRuleResult analyseLines(const LineProbe& probe, const Frame& driver, const Frame& reference) {
  const int w = probe.scene.width;
  const int h = probe.scene.height;
  checkSize(driver, w, h, "lines");
  checkSize(reference, w, h, "lines");
  LineRuleResult r;
  for (const LineProbeItem& item : probe.items) {
    // The item's pixels in each frame (image coordinates), and where they differ.
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = driver.index(x, y);
        const bool in_ref = reference.id[i] == item.primitive;
        const bool in_drv = driver.id[i] == item.primitive;
        const double cx = x + 0.5;
        const double cy = h - 1 - y + 0.5;
        if (item.kind == LineProbeItem::Kind::Thin) {
          r.thin_pixels += in_ref ? 1 : 0;
          if (in_ref == in_drv) continue;
          const bool x_major = std::fabs(item.b.x - item.a.x) >= std::fabs(item.b.y - item.a.y);
          const double mc = x_major ? cx : cy;
          const double ma = x_major ? item.a.x : item.a.y;
          const double mb = x_major ? item.b.x : item.b.y;
          const bool end = std::fabs(mc - ma) < 1.0 || std::fabs(mc - mb) < 1.0;
          (end ? r.thin_end_off : r.thin_interior_off) += 1;
        } else if (item.kind == LineProbeItem::Kind::Point) {
          r.point_pixels += in_ref ? 1 : 0;
          if (in_ref != in_drv) ++r.point_off;
        }
      }
    }
  }
  // Wide segments: fragments per column (x-major) or row inside, away from the ends.
  int lines_counted = 0;
  double per_line_sum = 0.0;
  for (const LineProbeItem& item : probe.items) {
    if (item.kind != LineProbeItem::Kind::Wide) continue;
    const bool x_major = std::fabs(item.b.x - item.a.x) >= std::fabs(item.b.y - item.a.y);
    const double lo = x_major ? std::min(item.a.x, item.b.x) : std::min(item.a.y, item.b.y);
    const double hi = x_major ? std::max(item.a.x, item.b.x) : std::max(item.a.y, item.b.y);
    int total = 0;
    int groups = 0;
    for (int m = static_cast<int>(lo) + 3; m <= static_cast<int>(hi) - 3; ++m) {
      int count = 0;
      const int other = x_major ? h : w;
      for (int n = 0; n < other; ++n) {
        const int x = x_major ? m : n;
        const int gy = x_major ? n : m;  // GL window y
        if (x < 0 || x >= w || gy < 0 || gy >= h) continue;
        if (driver.id[driver.index(x, h - 1 - gy)] == item.primitive) ++count;
      }
      total += count;
      ++groups;
    }
    if (groups == 0) continue;
    per_line_sum += static_cast<double>(total) / groups / item.size;
    ++lines_counted;
  }
  r.wide_per_column = lines_counted > 0 ? 4.0 * per_line_sum / lines_counted : 0.0;
  // 4 per column for the column rule; 4 / cos(30 deg) = 4.62 for a rectangle.
  r.wide_lines = std::fabs(r.wide_per_column - 4.0) < 0.15   ? "column"
                 : std::fabs(r.wide_per_column - 4.62) < 0.2 ? "rectangle"
                                                             : "other";
  r.line_rule = r.thin_interior_off == 0 && r.thin_end_off == 0 ? "diamond-exit"
                : r.thin_interior_off == 0                      ? "diamond-exit, own ends"
                                                                : "other";
  r.point_rule = r.point_off == 0 ? "square" : "other";
  // Ends of its own are GL's to allow (the reference's allowance takes them).
  r.matches_reference =
      r.line_rule != "other" && r.wide_lines == "column" && r.point_rule == "square";
  return r;
}

nlohmann::json toJson(const LineRuleResult& r) {
  const std::string summary =
      fmt::format("{}; wide: {}; points: {}", r.line_rule, r.wide_lines, r.point_rule);
  return {{"summary", summary},
          {"rule", summary},
          {"line_rule", r.line_rule},
          {"thin_pixels", r.thin_pixels},
          {"thin_interior_off", r.thin_interior_off},
          {"thin_end_off", r.thin_end_off},
          {"wide_lines", r.wide_lines},
          {"wide_per_column", r.wide_per_column},
          {"point_rule", r.point_rule},
          {"point_pixels", r.point_pixels},
          {"point_off", r.point_off},
          {"matches_reference", r.matches_reference}};
}

std::string describeLines(const LineRuleResult& r) {
  return fmt::format(
      "lines: {} ({} of {} one-pixel fragments differ inside, {} at the ends); wide lines: {} "
      "({:.2f} fragments per column at width 4); points: {} ({} of {} pixels differ){}",
      r.line_rule, r.thin_interior_off, r.thin_pixels, r.thin_end_off, r.wide_lines,
      r.wide_per_column, r.point_rule, r.point_off, r.point_pixels,
      r.matches_reference ? ", as the reference" : "");
}

std::map<int, Frame> subpixelReferences(const Scene& scene) {
  std::map<int, Frame> reference;
  for (int n = kMinCandidateBits; n <= kMaxCandidateBits; ++n) {
    ReferenceOptions options;
    options.subpixel_bits = n;
    options.uncertainty = false;
    reference[n] = renderReference(scene, options);
  }
  return reference;
}

nlohmann::json backendVariants(const Frame& sub, const Frame& tie_break,
                               const Frame& depth_rounding, const std::map<int, Frame>& reference) {
  nlohmann::json v = nlohmann::json::object();
  if (sub.meta.contains("renderer")) v["renderer"] = sub.meta["renderer"];
  if (sub.meta.contains("stack")) v["stack"] = sub.meta["stack"];
  auto key = [&](const char* name) {
    return sub.meta.contains(name) ? sub.meta[name] : nlohmann::json(nullptr);
  };
  // GL's answer; older frames carried it as subpixel_bits only.
  v["subpixel_bits"] =
      sub.meta.contains("gl_subpixel_bits") ? key("gl_subpixel_bits") : key("subpixel_bits");
  v["band_subpixel_bits"] = key("subpixel_bits");
  const SubpixelResult subpixel = analyseSubpixel(sub, reference);
  v["subpixel"] = toJson(subpixel);
  v["findings"] = nlohmann::json::array();
  if (!subpixel.finding.empty()) v["findings"].push_back("subpixel: " + subpixel.finding);
  // A band finer than the driver's snapping would call legal edge pixels hard; a
  // coarser one (softpipe's 4 bits over its float edges) only excuses more.
  if (subpixel.band >= 0 && subpixel.best >= 0 && !subpixel.band_confirmed &&
      subpixel.best < subpixel.band)
    v["findings"].push_back(fmt::format(
        "subpixel: the driver snaps to {} bits, coarser than the {} bits its frames carry "
        "for the snap band: legal edge pixels may be reported hard",
        subpixel.best, subpixel.band));
  v["tie_break"] = toJson(analyseTieBreak(tieBreakProbe(), tie_break));
  v["depth_rounding"] = toJson(analyseDepthRounding(depthProbe(), depth_rounding));
  return v;
}

}  // namespace rc::variants
