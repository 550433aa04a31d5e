// See variants.h (orchestration only; the probes and their analysis are in
// compare/variants.cpp).
#include "app/variants.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>

#include <fmt/format.h>

#include "app/backends.h"
#include "app/debug_support.h"
#include "compare/variants.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/scene_writer.h"

namespace rc {
namespace fs = std::filesystem;

nlohmann::json detectVariants(const std::vector<std::string>& specs, const fs::path& work_dir,
                              int parallel) {
  std::vector<std::string> gl_specs;
  for (const std::string& s : specs) {
    if (parseBackendSpec(s).kind != BackendSpec::Kind::Gl) continue;
    if (std::find(gl_specs.begin(), gl_specs.end(), s) == gl_specs.end()) gl_specs.push_back(s);
  }
  nlohmann::json out = nlohmann::json::object();
  if (gl_specs.empty()) return out;
  const auto start = std::chrono::steady_clock::now();

  // The probes go through a fixture file, like every GL render; the reference renders
  // the file's scene too, so both see exactly the same (float) vertices.
  const variants::TieBreakProbe tie = variants::tieBreakProbe();
  const variants::DepthProbe depth = variants::depthProbe();
  const std::map<std::string, Scene> probes = {{"subpixel", variants::subpixelProbe()},
                                               {"tie_break", tie.scene},
                                               {"depth_rounding", depth.scene}};
  const fs::path probe_dir = work_dir / "probes";
  fs::create_directories(probe_dir);
  std::map<std::string, fs::path> files;
  for (const auto& [name, scene] : probes) {
    files[name] = probe_dir / (name + ".json");
    writeSceneFile(scene, files[name]);
  }

  std::vector<Job> jobs;
  std::map<std::pair<std::string, std::string>, std::size_t> job_of;
  for (const std::string& spec : gl_specs) {
    const fs::path dir = work_dir / fixtureSlug(spec);
    fs::create_directories(dir);
    for (const auto& [name, file] : files) {
      job_of[{spec, name}] = jobs.size();
      jobs.push_back(renderJob(file, spec, dir / name));
    }
  }
  runJobs(jobs, parallel);

  // ref:subpixel=N for every candidate N, once for all backends.
  std::map<int, Frame> reference;
  const Scene subpixel_scene = loadScene(files["subpixel"]);
  for (int n = variants::kMinCandidateBits; n <= variants::kMaxCandidateBits; ++n) {
    ReferenceOptions options;
    options.subpixel_bits = n;
    options.uncertainty = false;
    reference[n] = renderReference(subpixel_scene, options);
  }
  const double shared_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  for (const std::string& spec : gl_specs) {
    nlohmann::json v = nlohmann::json::object();
    std::string error;
    for (const auto& [name, file] : files) {
      const Job& job = jobs[job_of[{spec, name}]];
      if (job.exit_code != 0 && error.empty()) error = name + " probe: " + childFailure(job);
    }
    if (!error.empty()) {
      out[spec] = {{"error", error}};
      continue;
    }
    try {
      const fs::path dir = work_dir / fixtureSlug(spec);
      const Frame sub = readFrameDir(dir / "subpixel");
      const Frame tb = readFrameDir(dir / "tie_break");
      const Frame dr = readFrameDir(dir / "depth_rounding");
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
      v["tie_break"] = variants::toJson(variants::analyseTieBreak(tie, tb));
      v["depth_rounding"] = variants::toJson(variants::analyseDepthRounding(depth, dr));
      v["probe_seconds"] = shared_seconds;
    } catch (const InputError& e) {
      v = {{"error", e.what()}};
    }
    out[spec] = v;
  }
  std::ofstream(work_dir / "variants.json") << out.dump(2) << '\n';
  return out;
}

}  // namespace rc
