// See variants.h (orchestration only; the probes and their analysis are in
// compare/variants.cpp).
#include "app/variants.h"

#include <algorithm>
#include <chrono>
#include <fstream>

#include <fmt/format.h>

#include "app/backends.h"
#include "compare/variants.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/scene_writer.h"

namespace rc {
namespace fs = std::filesystem;

namespace {

// The probes go through a fixture file, like every GL render; the reference renders
// the file's scene too, so both see exactly the same (float) vertices.
const std::map<std::string, Scene>& probeScenes() {
  static const std::map<std::string, Scene> probes = {
      {"subpixel", variants::subpixelProbe()},
      {"tie_break", variants::tieBreakProbe().scene},
      {"depth_rounding", variants::depthProbe().scene}};
  return probes;
}

}  // namespace

VariantProbes prepareVariantProbes(const std::vector<std::string>& specs,
                                   const fs::path& work_dir) {
  VariantProbes out;
  out.work_dir = work_dir;
  for (const std::string& s : specs) {
    if (parseBackendSpec(s).kind != BackendSpec::Kind::Gl) continue;
    if (std::find(out.gl_specs.begin(), out.gl_specs.end(), s) == out.gl_specs.end())
      out.gl_specs.push_back(s);
  }
  if (out.gl_specs.empty()) return out;
  const fs::path probe_dir = work_dir / "probes";
  fs::create_directories(probe_dir);
  for (const auto& [name, scene] : probeScenes()) {
    out.files[name] = fs::absolute(probe_dir / (name + ".json"));
    writeSceneFile(scene, out.files[name]);
  }
  for (const std::string& spec : out.gl_specs)
    for (const auto& [name, file] : out.files) out.requests.push_back({file, spec});
  return out;
}

nlohmann::json analyseVariants(const VariantProbes& probes,
                               const std::vector<RenderOutcome>& outcomes, double seconds) {
  nlohmann::json out = nlohmann::json::object();
  if (probes.gl_specs.empty()) return out;
  const auto start = std::chrono::steady_clock::now();
  // ref:subpixel=N for every candidate N, once for all backends.
  std::map<int, Frame> reference;
  const Scene subpixel_scene = loadScene(probes.files.at("subpixel"));
  for (int n = variants::kMinCandidateBits; n <= variants::kMaxCandidateBits; ++n) {
    ReferenceOptions options;
    options.subpixel_bits = n;
    options.uncertainty = false;
    reference[n] = renderReference(subpixel_scene, options);
  }
  const double shared_seconds =
      seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const variants::TieBreakProbe tie = variants::tieBreakProbe();
  const variants::DepthProbe depth = variants::depthProbe();

  for (const std::string& spec : probes.gl_specs) {
    std::map<std::string, const RenderOutcome*> got;
    for (std::size_t i = 0; i < probes.requests.size(); ++i) {
      if (probes.requests[i].spec != spec) continue;
      for (const auto& [name, file] : probes.files)
        if (file == probes.requests[i].fixture) got[name] = &outcomes[i];
    }
    std::string error;
    for (const auto& [name, outcome] : got)
      if (!outcome->ok && error.empty()) error = name + " probe: " + outcome->error;
    if (!error.empty()) {
      out[spec] = {{"error", error}};
      continue;
    }
    nlohmann::json v = nlohmann::json::object();
    try {
      const fs::path dir = probes.work_dir / fixtureSlug(spec);
      for (const auto& [name, outcome] : got) writeFrameDir(outcome->frame, dir / name);
      const Frame& sub = got.at("subpixel")->frame;
      if (sub.meta.contains("renderer")) v["renderer"] = sub.meta["renderer"];
      if (sub.meta.contains("stack")) v["stack"] = sub.meta["stack"];
      auto key = [&](const char* name) {
        return sub.meta.contains(name) ? sub.meta[name] : nlohmann::json(nullptr);
      };
      // GL's answer; older frames carried it as subpixel_bits only.
      v["subpixel_bits"] =
          sub.meta.contains("gl_subpixel_bits") ? key("gl_subpixel_bits") : key("subpixel_bits");
      v["band_subpixel_bits"] = key("subpixel_bits");
      const variants::SubpixelResult subpixel = variants::analyseSubpixel(sub, reference);
      v["subpixel"] = variants::toJson(subpixel);
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
      v["tie_break"] = variants::toJson(variants::analyseTieBreak(tie, got.at("tie_break")->frame));
      v["depth_rounding"] =
          variants::toJson(variants::analyseDepthRounding(depth, got.at("depth_rounding")->frame));
      v["probe_seconds"] = shared_seconds;
    } catch (const InputError& e) {
      v = {{"error", e.what()}};
    }
    out[spec] = v;
  }
  const fs::path file_path = probes.work_dir / "variants.json";
  std::ofstream file(file_path);
  file << out.dump(2) << '\n';
  if (!file.flush()) throw InputError(fmt::format("{}: cannot write", file_path.string()));
  return out;
}

}  // namespace rc
