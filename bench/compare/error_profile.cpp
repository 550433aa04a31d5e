// error_profile: how a driver's colour error relates to the colour's magnitude, for the
// derivation of the shading allowance (docs/tolerances.md). For every frame folder pair
// under a `rastercheck run` output (OUT/frames/<fixture>/{ref,<backend>}), over the
// pixels both sides draw with the same primitive: the largest per-channel error (8-bit
// units), the largest error relative to max(|Ca|, |Cb|) for channels >= 1/64, and the
// largest error of channels below 1/64.
//
//   build/release/bench/compare/error_profile OUT/frames [BACKEND_FOLDER...]
//   (default backend folders: gl_egl_llvmpipe gl_egl_softpipe)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "fixtures/errors.h"
#include "fixtures/frame_io.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT/frames [BACKEND_FOLDER...]\n", argv[0]);
    return 2;
  }
  std::vector<std::string> backends(argv + 2, argv + argc);
  if (backends.empty()) backends = {"gl_egl_llvmpipe", "gl_egl_softpipe"};
  std::vector<fs::path> fixtures;
  for (const auto& e : fs::directory_iterator(argv[1]))
    if (fs::exists(e.path() / "ref" / "frame.exr")) fixtures.push_back(e.path());
  std::sort(fixtures.begin(), fixtures.end());
  std::printf("%-44s %-18s %10s %12s %10s %12s\n", "fixture", "backend", "max units", "max rel",
              "at |C|", "small |C| max");
  try {
    for (const fs::path& dir : fixtures) {
      const rc::Frame e = rc::readFrameDir(dir / "ref");
      for (const std::string& b : backends) {
        if (!fs::exists(dir / b / "frame.exr")) continue;
        const rc::Frame a = rc::readFrameDir(dir / b);
        if (a.pixelCount() != e.pixelCount()) continue;
        double max_units = 0, max_rel = 0, rel_at = 0, small_max = 0;
        for (std::size_t i = 0; i < e.pixelCount(); ++i) {
          if (e.id[i] == 0 || e.id[i] != a.id[i]) continue;
          for (int c = 0; c < 4; ++c) {
            const double ca = e.color[i * 4 + c];
            const double cb = a.color[i * 4 + c];
            const double units = std::fabs(ca - cb) * 255.0;
            const double mag = std::max(std::fabs(ca), std::fabs(cb));
            if (!std::isfinite(units)) continue;
            max_units = std::max(max_units, units);
            if (mag >= 1.0 / 64.0) {
              const double rel = units / (255.0 * mag);
              if (rel > max_rel) {
                max_rel = rel;
                rel_at = mag;
              }
            } else {
              small_max = std::max(small_max, units);
            }
          }
        }
        std::printf("%-44s %-18s %10.5f %12.3g %10.3f %12.5f\n", dir.filename().c_str(), b.c_str(),
                    max_units, max_rel, rel_at, small_max);
      }
    }
  } catch (const rc::InputError& err) {
    std::fprintf(stderr, "error_profile: %s\n", err.what());
    return 2;
  }
  return 0;
}
