// CIEDE2000 per pixel and pooled: see ciede2000.h. The formula's steps are numbered as in
// Sharma, Wu and Dalal (2005), equations (1) to (17); angles are in degrees there and in
// radians here.
#include "compare/ciede2000.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <functional>
#include <numbers>
#include <thread>
#include <vector>

#include "compare/colour_space.h"
#include "compare/cube_root.h"

namespace rc {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kPow25To7 = 6103515625.0;  // 25^7

// C^7 / (C^7 + 25^7), the chroma weight of (4) and (17); its square root is taken there.
double chromaWeight(double c) {
  const double c2 = c * c;
  const double c7 = c2 * c2 * c2 * c;
  return c7 / (c7 + kPow25To7);
}

// The hue angle in [0, 2 pi) of (a', b) (5); 0 for a neutral colour (a' = b = 0).
double hueAngle(double b, double a_prime) {
  if (a_prime == 0.0 && b == 0.0) return 0.0;
  const double h = std::atan2(b, a_prime);
  return h >= 0.0 ? h : h + 2.0 * kPi;
}

double srgbDecode(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// CIELAB's f(t): the cube root above (6/29)^3 (compare/cube_root.h: a third of the time
// went to std::cbrt), its tangent line below.
double labF(double t) {
  constexpr double d = 6.0 / 29.0;
  return t > d * d * d ? cubeRoot(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

Lab linearToLab(const double rgb[3]) {
  double xyz[3];
  double white[3];
  for (int i = 0; i < 3; ++i) {
    xyz[i] = kRgbToXyz[i][0] * rgb[0] + kRgbToXyz[i][1] * rgb[1] + kRgbToXyz[i][2] * rgb[2];
    white[i] = kRgbToXyz[i][0] + kRgbToXyz[i][1] + kRgbToXyz[i][2];
  }
  const double fx = labF(xyz[0] / white[0]);
  const double fy = labF(xyz[1] / white[1]);
  const double fz = labF(xyz[2] / white[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

// The linear value of each 8-bit sRGB code (frames are read as 8-bit pictures).
const std::array<double, 256>& decodeTable() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = srgbDecode(i / 255.0);
    return t;
  }();
  return table;
}

// A pixel's 8-bit R, G, B as one key, and the CIELAB of a key.
std::uint32_t rgbKey(const float* rgba) {
  return static_cast<std::uint32_t>(colorByte(rgba[0])) << 16 |
         static_cast<std::uint32_t>(colorByte(rgba[1])) << 8 | colorByte(rgba[2]);
}
Lab keyLab(std::uint32_t key) {
  const std::array<double, 256>& decode = decodeTable();
  const double rgb[3] = {decode[key >> 16], decode[(key >> 8) & 0xffu], decode[key & 0xffu]};
  return linearToLab(rgb);
}

// Sorts positive finite doubles (their bit patterns order as the values do): a least
// significant digit radix sort, 8 bits a pass, passes in which every value has the same
// digit skipped (the sign and most exponent bits). A few times faster than std::sort on a
// whole 1080p frame of differences, which is what pooling costs when every pixel differs.
void sortPositive(std::vector<double>& values) {
  std::vector<std::uint64_t> keys(values.size());
  std::vector<std::uint64_t> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) keys[i] = std::bit_cast<std::uint64_t>(values[i]);
  for (int shift = 0; shift < 64; shift += 8) {
    std::array<std::size_t, 256> start{};
    for (const std::uint64_t k : keys) ++start[(k >> shift) & 0xffu];
    if (start[keys.front() >> shift & 0xffu] == keys.size()) continue;  // one digit: in order
    std::size_t sum = 0;
    for (std::size_t& c : start) {
      const std::size_t count = c;
      c = sum;
      sum += count;
    }
    for (const std::uint64_t k : keys) out[start[(k >> shift) & 0xffu]++] = k;
    keys.swap(out);
  }
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::bit_cast<double>(keys[i]);
}

// The answer cache of deltaE2000Frames(): 2^16 slots (1 MB a thread), a colour pair's slot
// from a multiplicative hash of both keys.
constexpr std::size_t kCacheSize = std::size_t{1} << 16;
std::size_t pairSlot(std::uint32_t e, std::uint32_t a) {
  const std::uint64_t k = (static_cast<std::uint64_t>(e) << 24 | a) * 0x9E3779B97F4A7C15ull;
  return static_cast<std::size_t>(k >> 48);
}

}  // namespace

double ciede2000(const Lab& x, const Lab& y) {
  // (2)-(4): a' scaled up by G, which grows as the mean chroma falls (near-neutral blues).
  // (Plain square roots instead of std::hypot: Lab values are far from overflow.)
  const double c_mean = 0.5 * (std::sqrt(x.a * x.a + x.b * x.b) + std::sqrt(y.a * y.a + y.b * y.b));
  const double g = 0.5 * (1.0 - std::sqrt(chromaWeight(c_mean)));
  const double a1 = (1.0 + g) * x.a;
  const double a2 = (1.0 + g) * y.a;
  // (5)-(6)
  const double c1 = std::sqrt(a1 * a1 + x.b * x.b);
  const double c2 = std::sqrt(a2 * a2 + y.b * y.b);
  const double h1 = hueAngle(x.b, a1);
  const double h2 = hueAngle(y.b, a2);
  const double c_product = c1 * c2;
  // (8)-(10): the hue difference the short way round the circle; none when either colour
  // is neutral.
  const double d_l = y.l - x.l;
  const double d_c = c2 - c1;
  double d_h = 0.0;
  if (c_product != 0.0) {
    d_h = h2 - h1;
    if (d_h > kPi) {
      d_h -= 2.0 * kPi;
    } else if (d_h < -kPi) {
      d_h += 2.0 * kPi;
    }
  }
  const double d_big_h = 2.0 * std::sqrt(c_product) * std::sin(0.5 * d_h);
  // (12)-(14): means; the mean hue is taken across 0 when the two hues are more than half
  // a turn apart, and is their sum when either colour is neutral.
  const double l_mean = 0.5 * (x.l + y.l);
  const double c_prime_mean = 0.5 * (c1 + c2);
  double h_mean = h1 + h2;
  if (c_product != 0.0) {
    if (std::fabs(h1 - h2) <= kPi) {
      h_mean = 0.5 * (h1 + h2);
    } else if (h1 + h2 < 2.0 * kPi) {
      h_mean = 0.5 * (h1 + h2 + 2.0 * kPi);
    } else {
      h_mean = 0.5 * (h1 + h2 - 2.0 * kPi);
    }
  }
  // (15)-(17)
  // T from cos and sin of the mean hue alone (multiple-angle identities: one sin/cos pair
  // instead of four cosines, the same value to ~1e-15).
  const double cos1 = std::cos(h_mean);
  const double sin1 = std::sin(h_mean);
  const double cos2 = 2.0 * cos1 * cos1 - 1.0;
  const double sin2 = 2.0 * sin1 * cos1;
  const double cos3 = cos1 * cos2 - sin1 * sin2;
  const double sin3 = sin1 * cos2 + cos1 * sin2;
  const double cos4 = cos2 * cos2 - sin2 * sin2;
  const double sin4 = 2.0 * sin2 * cos2;
  // cos(x - d) = cos x cos d + sin x sin d; cos(x + d) = cos x cos d - sin x sin d.
  static const double cos30 = std::cos(30.0 * kDeg), sin30 = std::sin(30.0 * kDeg);
  static const double cos6 = std::cos(6.0 * kDeg), sin6 = std::sin(6.0 * kDeg);
  static const double cos63 = std::cos(63.0 * kDeg), sin63 = std::sin(63.0 * kDeg);
  const double t = 1.0 - 0.17 * (cos1 * cos30 + sin1 * sin30) + 0.24 * cos2 +
                   0.32 * (cos3 * cos6 - sin3 * sin6) - 0.20 * (cos4 * cos63 + sin4 * sin63);
  const double hue_offset = (h_mean / kDeg - 275.0) / 25.0;
  const double d_theta = 30.0 * kDeg * std::exp(-hue_offset * hue_offset);
  const double r_c = 2.0 * std::sqrt(chromaWeight(c_prime_mean));
  const double l50 = (l_mean - 50.0) * (l_mean - 50.0);
  const double s_l = 1.0 + 0.015 * l50 / std::sqrt(20.0 + l50);
  const double s_c = 1.0 + 0.045 * c_prime_mean;
  const double s_h = 1.0 + 0.015 * c_prime_mean * t;
  const double r_t = -std::sin(2.0 * d_theta) * r_c;
  const double l_term = d_l / s_l;
  const double c_term = d_c / s_c;
  const double h_term = d_big_h / s_h;
  const double sum = l_term * l_term + c_term * c_term + h_term * h_term + r_t * c_term * h_term;
  return std::sqrt(std::max(sum, 0.0));
}

Lab srgbToLab(double r, double g, double b) {
  const double rgb[3] = {srgbDecode(r), srgbDecode(g), srgbDecode(b)};
  return linearToLab(rgb);
}

DeltaE2000Stats deltaE2000Frames(const Frame& expected, const Frame& actual) {
  DeltaE2000Stats s;
  const std::size_t n = std::min(expected.pixelCount(), actual.pixelCount());
  if (n == 0) return s;
  // Two halves of the image on two threads when it is large (a frame where every pixel
  // differs costs ~0.5 us a pixel); the split is fixed, so the sums do not depend on timing.
  struct Part {
    std::vector<double> values;  // the non-zero differences: zeros move no weighted percentile
    double total = 0.0;
    double max = 0.0;
    std::size_t worst = 0;
  };
  auto scan = [&](std::size_t begin, std::size_t end, Part& part) {
    // The same pair of 8-bit colours comes back often (flat shading, one colour mapped to
    // another by a lighting difference): a direct-mapped cache of answers by colour pair.
    struct Cached {
      std::uint32_t e = 0xffffffffu;  // no 24-bit key
      std::uint32_t a = 0xffffffffu;
      double d = 0.0;
    };
    std::vector<Cached> cache;  // allocated at the first differing pixel
    for (std::size_t i = begin; i < end; ++i) {
      const float* pe = &expected.color[4 * i];
      const float* pa = &actual.color[4 * i];
      if (pe[0] == pa[0] && pe[1] == pa[1] && pe[2] == pa[2]) continue;  // most pixels
      const std::uint32_t ek = rgbKey(pe);
      const std::uint32_t ak = rgbKey(pa);
      if (ek == ak) continue;
      if (cache.empty()) cache.resize(kCacheSize);
      Cached& c = cache[pairSlot(ek, ak)];
      if (c.e != ek || c.a != ak) c = {ek, ak, ciede2000(keyLab(ek), keyLab(ak))};
      part.values.push_back(c.d);
      part.total += c.d;
      if (c.d > part.max) {
        part.max = c.d;
        part.worst = i;
      }
    }
  };
  constexpr std::size_t kParallelPixels = std::size_t{1} << 18;
  Part parts[2];
  if (n >= kParallelPixels) {
    std::thread second(scan, n / 2, n, std::ref(parts[1]));
    scan(0, n / 2, parts[0]);
    second.join();
  } else {
    scan(0, n, parts[0]);
  }
  std::vector<double>& values = parts[0].values;
  values.insert(values.end(), parts[1].values.begin(), parts[1].values.end());
  parts[1].values = {};
  const double total = parts[0].total + parts[1].total;
  const Part& top = parts[1].max > parts[0].max ? parts[1] : parts[0];  // first on ties
  if (top.max > 0.0) {
    s.max = top.max;
    s.worst_x = static_cast<int>(top.worst % static_cast<std::size_t>(expected.width));
    s.worst_y = static_cast<int>(top.worst / static_cast<std::size_t>(expected.width));
  }
  s.differing = values.size();
  s.mean = total / static_cast<double>(n);
  if (values.empty()) return s;
  sortPositive(values);
  s.min = values.size() == n ? values.front() : 0.0;
  if (total <= 0.0) return s;
  const double fractions[3] = {0.25, 0.5, 0.75};
  double* targets[3] = {&s.weighted_q1, &s.weighted_median, &s.weighted_q3};
  double cum = 0.0;
  int next = 0;
  for (const double v : values) {
    cum += v;
    while (next < 3 && cum >= fractions[next] * total) *targets[next++] = v;
    if (next == 3) break;
  }
  while (next < 3) *targets[next++] = s.max;  // rounding of the running sum
  return s;
}

nlohmann::json deltaE2000Json(const DeltaE2000Stats& s, int height) {
  const bool worst = s.worst_x >= 0;
  return {
      {"mean", s.mean},
      {"weighted_median", s.weighted_median},
      {"weighted_q1", s.weighted_q1},
      {"weighted_q3", s.weighted_q3},
      {"min", s.min},
      {"max", s.max},
      {"differing", s.differing},
      {"worst", worst ? nlohmann::json::array({s.worst_x, s.worst_y}) : nlohmann::json(nullptr)},
      {"worst_window", worst ? nlohmann::json::array({s.worst_x, height - 1 - s.worst_y})
                             : nlohmann::json(nullptr)}};
}

}  // namespace rc
