// Variant detection for `run`: renders the probes of compare/variants.h with every GL
// backend (each render in a child process, several at a time) and the subpixel probe
// with the reference at every candidate precision (in this process), and analyses them.
// Done once per backend per run; the probe fixtures and frames stay under the run's
// output folder for anyone who wants to look.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rc {

// Returns {"SPEC": {...}} for every GL spec among `specs` (reference specs are skipped;
// duplicates are probed once): "renderer", "stack" (frame.json's one-line driver stack),
// "subpixel_bits" (GL_SUBPIXEL_BITS as the driver answers it), "band_subpixel_bits" (what
// the backend's frames carry for the comparator's snap band), "subpixel", "tie_break",
// "depth_rounding" (see compare/variants.h toJson), "findings" (sentences: where the
// driver's answer and its rasterization disagree) and "probe_seconds"; or "error" when a
// probe render failed.
// Writes work_dir/probes/*.json, work_dir/<spec>/<probe>/ frames and
// work_dir/variants.json. Never throws for a backend that cannot run.
nlohmann::json detectVariants(const std::vector<std::string>& specs,
                              const std::filesystem::path& work_dir, int parallel);

}  // namespace rc
