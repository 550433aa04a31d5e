// Error histograms: fine bins that give percentiles without sorting millions of values,
// and the coarse power-of-two bins the reports print.
#pragma once

#include <cstdint>
#include <vector>

namespace rc {

// Bins non-negative finite values. The first 1024 bins are `quantum` wide; above
// 1024 * quantum, each octave has 64 bins (1/64 relative width).
//
// With exact_multiples (every value an integer multiple of quantum, as integer depth steps
// or 8-bit colour differences are), percentiles are exact below 1024 * quantum; otherwise
// a percentile is the upper edge of its bin, so at most one quantum (or 1/64 relative)
// above the true value, and never above the largest value added.
class ErrorHistogram {
 public:
  ErrorHistogram(double quantum, bool exact_multiples);

  void add(double value) { ++bins_[binOf(value)]; }
  void add(double value, std::uint64_t count) { bins_[binOf(value)] += count; }
  // Adds `count` values v with floor(v / quantum) == bin < kLinearBins, for callers that
  // count small values in their own tables first.
  void addToLinearBin(int bin, std::uint64_t count) { bins_[bin] += count; }
  void merge(const ErrorHistogram& other);
  std::uint64_t count() const;

  // Nearest-rank percentile (p in [0, 1]) given the largest value added.
  double percentile(double p, double max_value) const;

  // Power-of-two bins for reports: edges 0, q, 2q, 4q, ... up to the first edge above
  // max_value; counts[i] holds values in [edges[i], edges[i + 1]).
  struct Coarse {
    std::vector<double> edges;
    std::vector<std::uint64_t> counts;
  };
  Coarse coarse(double max_value) const;

  double quantum() const { return quantum_; }
  bool exactMultiples() const { return exact_; }

  static constexpr int kLinearBins = 1024;

 private:
  static constexpr int kSubBins = 64;
  static constexpr int kOctaves = 64;

  int binOf(double value) const {
    const double u = value * inverse_quantum_;
    if (u < kLinearBins) return u > 0.0 ? static_cast<int>(u) : 0;
    return logBin(u);
  }
  int logBin(double u) const;
  double lowerEdge(int bin) const;
  double upperEdge(int bin) const;

  double quantum_;
  double inverse_quantum_;
  bool exact_;
  std::vector<std::uint64_t> bins_;
};

}  // namespace rc
