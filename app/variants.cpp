// See variants.h (orchestration only: files and worker renders; the probes, their
// analysis and the reference renders they are matched against are in debug/variants.cpp).
#include "app/variants.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <fstream>

#include <fmt/format.h>

#include "app/backends.h"
#include "debug/variants.h"
#include "fixtures/catalog.h"
#include "fixtures/errors.h"
#include "fixtures/frame_io.h"
#include "fixtures/loader.h"
#include "fixtures/scene_writer.h"
#include "reference/reference_renderer.h"

namespace rc {
namespace fs = std::filesystem;

namespace {

// A quad with polygon offset in a `format` buffer: its GL render measures the driver's r
// (frame.json polygon_offset_r, docs/gl_backend.md "Polygon offset's r, measured").
Scene offsetProbe(DepthFormat format) {
  Scene s;
  s.name = fmt::format("probe/polygon_offset_{}", toString(format));
  s.width = 8;
  s.height = 8;
  s.camera.projection = Projection::Orthographic;
  s.camera.eye = {0.0, 0.0, 1.0};
  s.camera.bounds = {0.0, 8.0, 0.0, 8.0};
  s.camera.near = 0.5;
  s.camera.far = 1.5;
  s.ambient_light = glm::dvec3(1.0);
  s.materials.push_back(Material{});
  s.materials.back().name = "default";
  Object o;
  o.name = "quad";
  o.mesh.positions = {{-1, -1, 0}, {9, -1, 0}, {9, 9, 0}, {-1, 9, 0}};
  o.mesh.normals.assign(4, glm::vec3(0, 0, 1));
  o.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  s.objects.push_back(o);
  s.state.depth_format = format;
  s.state.ops.polygon_offset = PolygonOffset{0.0, 1.0};
  return s;
}

constexpr std::array kOffsetProbes = {std::pair{"polygon_offset_d16", DepthFormat::D16},
                                      std::pair{"polygon_offset_d24", DepthFormat::D24},
                                      std::pair{"polygon_offset_d32f", DepthFormat::D32F}};

// The probes go through a fixture file, like every GL render; the reference renders
// the file's scene too, so both see exactly the same (float) vertices.
const std::map<std::string, Scene>& probeScenes() {
  static const std::map<std::string, Scene> probes = [] {
    std::map<std::string, Scene> p = {{"subpixel", variants::subpixelProbe()},
                                      {"tie_break", variants::tieBreakProbe().scene},
                                      {"depth_rounding", variants::depthProbe().scene},
                                      {"lines", variants::lineProbe().scene}};
    for (const auto& [name, format] : kOffsetProbes) p[name] = offsetProbe(format);
    return p;
  }();
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
  const std::map<int, Frame> reference =
      variants::subpixelReferences(loadScene(probes.files.at("subpixel")));
  const double shared_seconds =
      seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

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
      v = variants::backendVariants(got.at("subpixel")->frame, got.at("tie_break")->frame,
                                    got.at("depth_rounding")->frame, reference);
      // Polygon offset's r per depth format, as each render measured it.
      nlohmann::json r = nlohmann::json::object();
      for (const auto& [name, format] : kOffsetProbes) {
        const nlohmann::json& meta = got.at(name)->frame.meta;
        const auto it = meta.find("polygon_offset_r");
        r[toString(format)] = it != meta.end() ? *it : nlohmann::json(nullptr);
        if (it != meta.end() && it->is_number() && it->get<double>() < 1.0)
          v["findings"].push_back(fmt::format(
              "polygon offset: r for {} is {} of the format's minimum resolvable difference "
              "(below 1: an offset of one unit may not separate two depths)",
              toString(format), it->get<double>()));
      }
      v["polygon_offset_r"] = r;
      // Lines and points, against the reference's frame of the same file.
      ReferenceOptions line_options;
      line_options.uncertainty = false;
      const variants::LineRuleResult lines = variants::analyseLines(
          variants::lineProbe(), got.at("lines")->frame,
          renderReference(loadScene(probes.files.at("lines")), line_options));
      v["lines"] = variants::toJson(lines);
      if (!lines.matches_reference) v["findings"].push_back(variants::describeLines(lines));
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
