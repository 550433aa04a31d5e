// Error histograms: see histogram.h.
#include "compare/histogram.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace rc {

ErrorHistogram::ErrorHistogram(double quantum, bool exact_multiples)
    : quantum_(quantum),
      inverse_quantum_(1.0 / quantum),
      exact_(exact_multiples),
      bins_(kLinearBins + kOctaves * kSubBins, 0) {}

int ErrorHistogram::logBin(double u) const {
  if (!(u < 0x1p63)) return static_cast<int>(bins_.size()) - 1;  // also catches NaN
  int e = 0;
  const double m = std::frexp(u, &e);  // u = m * 2^e, m in [0.5, 1), e >= 11 here
  const int sub = std::min(kSubBins - 1, static_cast<int>((m * 2.0 - 1.0) * kSubBins));
  const int bin = kLinearBins + (e - 11) * kSubBins + sub;
  return std::min(bin, static_cast<int>(bins_.size()) - 1);
}

double ErrorHistogram::lowerEdge(int bin) const {
  if (bin < kLinearBins) return bin * quantum_;
  const int octave = (bin - kLinearBins) / kSubBins;
  const int sub = (bin - kLinearBins) % kSubBins;
  return quantum_ * std::ldexp(1.0 + static_cast<double>(sub) / kSubBins, octave + 10);
}

double ErrorHistogram::upperEdge(int bin) const { return lowerEdge(bin + 1); }

void ErrorHistogram::merge(const ErrorHistogram& other) {
  for (std::size_t i = 0; i < bins_.size(); ++i) bins_[i] += other.bins_[i];
}

std::uint64_t ErrorHistogram::count() const {
  return std::accumulate(bins_.begin(), bins_.end(), std::uint64_t{0});
}

double ErrorHistogram::percentile(double p, double max_value) const {
  const std::uint64_t n = count();
  if (n == 0) return 0.0;
  const auto rank = std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>(std::ceil(std::clamp(p, 0.0, 1.0) * static_cast<double>(n))));
  std::uint64_t seen = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    seen += bins_[bin];
    if (seen >= rank) {
      const int b = static_cast<int>(bin);
      if (bin + 1 == bins_.size()) return max_value;  // the overflow bin has no upper edge
      // Every bin's edges are multiples of the quantum, so in exact mode the largest value
      // the bin can hold is its upper edge minus one quantum.
      const double top = exact_ ? upperEdge(b) - quantum_ : upperEdge(b);
      return std::min(top, max_value);
    }
  }
  return max_value;
}

ErrorHistogram::Coarse ErrorHistogram::coarse(double max_value) const {
  Coarse c;
  c.edges.push_back(0.0);
  double edge = quantum_;
  while (true) {
    c.edges.push_back(edge);
    if (edge > max_value || edge >= lowerEdge(static_cast<int>(bins_.size()) - 1)) break;
    edge *= 2.0;
  }
  c.counts.assign(c.edges.size() - 1, 0);
  // Coarse edges fall on fine-bin edges (q * 2^k), so each fine bin lies in one coarse bin.
  std::size_t slot = 0;
  for (std::size_t bin = 0; bin < bins_.size(); ++bin) {
    if (bins_[bin] == 0) continue;
    const double lo = lowerEdge(static_cast<int>(bin));
    while (slot + 1 < c.counts.size() && lo >= c.edges[slot + 1]) ++slot;
    c.counts[slot] += bins_[bin];
  }
  return c;
}

}  // namespace rc
