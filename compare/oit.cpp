// The A-buffer comparison: see oit.h.
#include "compare/oit.h"

#include <algorithm>
#include <cmath>

namespace rc {

std::optional<OitStats> compareOit(const Frame& expected, const Frame& actual,
                                   const Tolerances& tolerances) {
  const auto meta = expected.meta.find("abuffer");
  if (meta == expected.meta.end() || !meta->is_object()) return std::nullopt;
  OitStats s;
  s.threshold = tolerances.shading.warn;
  auto count = [&](const char* key) -> std::uint64_t {
    const auto it = meta->find(key);
    return it != meta->end() && it->is_number_integer() && it->get<std::int64_t>() >= 0
               ? it->get<std::uint64_t>()
               : 0;
  };
  s.unsorted_pixels = count("unsorted_pixels");
  s.pairs_total = count("out_of_order_pairs");
  if (const auto list = meta->find("out_of_order"); list != meta->end() && list->is_array()) {
    for (const nlohmann::json& p : *list) {
      if (!p.is_object()) continue;
      OitPair pair;
      pair.near_id = p.value("near", 0u);
      pair.far_id = p.value("far", 0u);
      pair.pixels = p.value("pixels", std::uint64_t{0});
      if (const auto f = p.find("first"); f != p.end() && f->is_array() && f->size() == 2) {
        pair.first_x = (*f)[0].get<int>();
        pair.first_y = (*f)[1].get<int>();
      }
      s.out_of_order.push_back(pair);
    }
  }
  const bool blend_counts = expected.blend_count.size() == expected.pixelCount();
  double sum = 0.0;
  const std::size_t n = std::min(expected.pixelCount(), actual.pixelCount());
  for (std::size_t i = 0; i < n; ++i) {
    double err = 0.0;
    for (int c = 0; c < 4; ++c) {
      const double d =
          std::fabs(double{expected.color[4 * i + c]} - actual.color[4 * i + c]) * 255.0;
      err = std::max(err, std::isnan(d) ? HUGE_VAL : d);
    }
    if (err > s.threshold) ++s.pixels;
    if (err > s.max_abs) {
      s.max_abs = err;
      s.worst_x = static_cast<int>(i % static_cast<std::size_t>(expected.width));
      s.worst_y = static_cast<int>(i / static_cast<std::size_t>(expected.width));
    }
    if (blend_counts && expected.blend_count[i] > 0.0f) {
      ++s.blended_pixels;
      sum += err;
    }
  }
  if (s.blended_pixels > 0) s.mean_abs = sum / static_cast<double>(s.blended_pixels);
  return s;
}

nlohmann::json oitJson(const OitStats& s, int height) {
  auto pixel = [&](int x, int y) {
    return x < 0 ? nlohmann::json(nullptr) : nlohmann::json::array({x, y});
  };
  nlohmann::json pairs = nlohmann::json::array();
  for (const OitPair& p : s.out_of_order)
    pairs.push_back({{"near", p.near_id},
                     {"far", p.far_id},
                     {"pixels", p.pixels},
                     {"first", pixel(p.first_x, p.first_y)}});
  return {
      {"blended_pixels", s.blended_pixels},
      {"unsorted_pixels", s.unsorted_pixels},
      {"pixels", s.pixels},
      {"threshold", s.threshold},
      {"max_abs", std::isfinite(s.max_abs) ? nlohmann::json(s.max_abs) : nlohmann::json(nullptr)},
      {"mean_abs",
       std::isfinite(s.mean_abs) ? nlohmann::json(s.mean_abs) : nlohmann::json(nullptr)},
      {"worst", pixel(s.worst_x, s.worst_y)},
      {"worst_window", s.worst_x < 0 ? nlohmann::json(nullptr)
                                     : nlohmann::json::array({s.worst_x, height - 1 - s.worst_y})},
      {"out_of_order_pairs", s.pairs_total},
      {"out_of_order", pairs}};
}

}  // namespace rc
