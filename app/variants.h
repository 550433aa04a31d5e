// Variant detection for `run`: the probes of debug/variants.h rendered with every GL
// backend (by the run's workers, app/worker_pool.h) and the subpixel probe with the
// reference at every candidate precision (in this process), then analysed. Done once
// per backend per run; the probe fixtures and frames stay under the run's output folder
// for anyone who wants to look.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/worker_pool.h"

namespace rc {

// The probe renders of one run: written as fixture files under work_dir/probes/.
struct VariantProbes {
  std::filesystem::path work_dir;
  std::vector<std::string> gl_specs;                   // the GL specs among those given, once
  std::map<std::string, std::filesystem::path> files;  // probe name -> fixture file
  std::vector<RenderRequest> requests;                 // every probe with every GL spec
};

// Writes the probe fixtures for every GL spec among `specs` (reference specs are
// skipped; duplicates are probed once). No requests when there is no GL spec.
VariantProbes prepareVariantProbes(const std::vector<std::string>& specs,
                                   const std::filesystem::path& work_dir);

// Returns {"SPEC": {...}} for every probed spec: "renderer", "stack" (frame.json's one-line
// driver stack), "subpixel_bits" (GL_SUBPIXEL_BITS as the driver answers it),
// "band_subpixel_bits" (what the backend's frames carry for the comparator's snap band),
// "subpixel", "tie_break", "depth_rounding" (see debug/variants.h toJson), "findings"
// (sentences: where the driver's answer and its rasterization disagree) and
// "probe_seconds"; or "error" when a probe render failed. `outcomes` are those of
// probes.requests, in order; `seconds` is the time the probes took. Writes
// work_dir/<spec>/<probe>/ frames and work_dir/variants.json. Never throws for a backend
// that could not run.
nlohmann::json analyseVariants(const VariantProbes& probes,
                               const std::vector<RenderOutcome>& outcomes, double seconds);

}  // namespace rc
