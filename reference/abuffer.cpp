// ref:abuffer: exact order-independent transparency. The blended fragments the fragment
// loop kept are sorted per pixel and blended far to near; frame.json "abuffer" says where the
// draw order was not the depth order.
#include "reference/renderer_internal.h"

namespace rc::ref {
namespace {

// frame.json "abuffer.out_of_order" lists at most this many triangle pairs (most pixels
// first); "out_of_order_pairs" counts them all.
constexpr std::size_t kMaxReportedPairs = 64;

}  // namespace

// The A-buffer's resolve: each pixel's kept fragments sorted far to near (window depth,
// ties in draw order: the order the sorted-triangle pass would blend them in), blended in
// that order through writeColor() (so that where the orders agree the colour is bit for
// bit the plain reference's), the nearest one as the id. Also the uncertainty channels of
// that order (UncertaintyTracker::sortedList) and which triangles the draw order blends
// out of depth order (abuffer_, for frame.json "abuffer").
void Renderer::resolveABuffer() {
  defer_blends_ = false;
  std::stable_sort(kept_.begin(), kept_.end(), [](const KeptFragment& a, const KeptFragment& b) {
    if (a.index != b.index) return a.index < b.index;
    if (a.z != b.z) return a.z > b.z;
    return a.seq < b.seq;
  });
  abuffer_.pixel_flags.assign(frame_.pixelCount(), 0);
  abuffer_.kept_fragments = kept_.size();
  std::vector<double> z;
  std::vector<float> slope;
  const std::size_t pairs_before = abuffer_.pair_pixels.size();
  for (std::size_t b = 0; b < kept_.size();) {
    std::size_t e = b;
    while (e < kept_.size() && kept_[e].index == kept_[b].index) ++e;
    const std::size_t index = kept_[b].index;
    abuffer_.pixel_flags[index] |= ABufferTally::kBlended;
    z.clear();
    slope.clear();
    for (std::size_t k = b; k < e; ++k) {
      const KeptFragment& f = kept_[k];
      writeColor(index, f.color, true);
      if (uncertainty_)
        gaps_.colourWritten(index, true, f.alpha, f.note.dist, f.note.alt, f.note.gain,
                            f.note.reach, f.note.shade, f.note.normal);
      z.push_back(f.z);
      slope.push_back(f.slope);
      if (sorted_ != nullptr) sorted_->push_back({f.id, f.seq, f.z, f.color, storedColor(index)});
    }
    frame_.id[index] = kept_[e - 1].id;
    if (uncertainty_) gaps_.sortedList(index, z.data(), slope.data(), z.size());
    // Inversions: a farther fragment (earlier in the list) drawn after a nearer one.
    for (std::size_t i = b; i < e; ++i) {
      for (std::size_t j = i + 1; j < e; ++j) {
        if (kept_[i].seq > kept_[j].seq && kept_[i].id != kept_[j].id) {
          abuffer_.pixel_flags[index] |= ABufferTally::kUnsorted;
          abuffer_.pair_pixels.push_back(
              {kept_[j].id, kept_[i].id, static_cast<std::uint32_t>(index)});
        }
      }
    }
    b = e;
  }
  // Each (pair, pixel) once: pixels come in increasing order, so sorting this frame's
  // entries keeps them grouped by pair and ordered by pixel within a pair.
  std::sort(abuffer_.pair_pixels.begin() + static_cast<std::ptrdiff_t>(pairs_before),
            abuffer_.pair_pixels.end());
  abuffer_.pair_pixels.erase(
      std::unique(abuffer_.pair_pixels.begin() + static_cast<std::ptrdiff_t>(pairs_before),
                  abuffer_.pair_pixels.end()),
      abuffer_.pair_pixels.end());
  kept_ = {};
}

// frame.json "abuffer" from a tally over the framebuffer rectangle `clip` of an image
// `image_height` rows high: pixel counts, and the out-of-order triangle pairs (most pixels
// first, ties by ids; each with the first pixel in framebuffer order, image coordinates).
nlohmann::json abufferMeta(ABufferTally& tally, const PixelRect& clip, int image_height) {
  std::uint64_t blended_pixels = 0;
  std::uint64_t unsorted_pixels = 0;
  for (const std::uint8_t f : tally.pixel_flags) {
    blended_pixels += (f & ABufferTally::kBlended) != 0 ? 1 : 0;
    unsorted_pixels += (f & ABufferTally::kUnsorted) != 0 ? 1 : 0;
  }
  std::vector<ABufferTally::PairPixel>& pp = tally.pair_pixels;
  std::sort(pp.begin(), pp.end());
  pp.erase(std::unique(pp.begin(), pp.end()), pp.end());
  struct PairCount {
    std::uint32_t near = 0;
    std::uint32_t far = 0;
    std::uint64_t pixels = 0;
    std::uint32_t first = 0;  // pixel index
  };
  std::vector<PairCount> list;
  for (const ABufferTally::PairPixel& p : pp) {
    if (list.empty() || list.back().near != p.near || list.back().far != p.far)
      list.push_back({p.near, p.far, 0, p.index});
    ++list.back().pixels;
  }
  std::stable_sort(list.begin(), list.end(),
                   [](const PairCount& a, const PairCount& b) { return a.pixels > b.pixels; });
  const auto width = static_cast<std::uint32_t>(clip.x1 - clip.x0);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < list.size() && k < kMaxReportedPairs; ++k) {
    const std::uint32_t first = list[k].first;
    const int x = clip.x0 + static_cast<int>(first % width);
    const int y = (image_height - clip.y1) + static_cast<int>(first / width);
    out.push_back({{"near", list[k].near},
                   {"far", list[k].far},
                   {"pixels", list[k].pixels},
                   {"first", {x, y}}});
  }
  return {{"kept_fragments", tally.kept_fragments},
          {"blended_pixels", blended_pixels},
          {"unsorted_pixels", unsorted_pixels},
          {"out_of_order_pairs", list.size()},
          {"out_of_order", std::move(out)}};
}

}  // namespace rc::ref
