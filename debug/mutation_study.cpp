// The mutation study's faults, verdicts, tallies and report: see mutation_study.h.
#include "debug/mutation_study.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "fixtures/errors.h"
#include "fixtures/random_stream.h"

namespace rc {
using nlohmann::json;

namespace {

constexpr std::array<MutationFault, 17> kFaults = {{
    {"light_scale", "shading", "every light 1% brighter"},
    {"depth_bias", "depth", "stored depth 4 x the fail threshold further (8 d16 / 64 d24 steps)"},
    {"drop_primitive", "visibility", "one visible triangle not drawn"},
    {"move_vertex", "visibility", "one vertex of one visible triangle one pixel right"},
    {"texel_offset", "shading", "textures sampled one texel to the right"},
    {"blend_factor", "shading", "alpha blending with GL_ONE instead of GL_SRC_ALPHA"},
    {"depth_func", "visibility", "wrong depth function: LESS and GREATER (and the others) swapped"},
    {"stencil_op", "depth", "stencil op off by one: each op the next in GL's list"},
    {"blend_function", "shading",
     "wrong blend factor: each blend function's source factor the next"},
    {"scissor_shift", "visibility", "scissor box one pixel off (to the right)"},
    {"lod_shift", "shading", "level of detail one level off (GL_TEXTURE_LOD_BIAS + 1)"},
    {"lod_weight", "shading", "two mip levels blended with the weight inverted (1 - f for f)"},
    {"move_line_end", "visibility",
     "one end of one visible line segment one pixel off, across the segment"},
    {"move_point", "visibility", "one visible point one pixel right"},
    {"shadow_shift", "shading", "shadow lookups one map texel to the right (the map offset)"},
    {"shadow_compare", "shading",
     "shadow comparison inverted (LEQUAL and GEQUAL, LESS and GREATER swapped)"},
    {"shadow_bias", "shading", "shadow lookups without their bias"},
}};

constexpr std::array<MutationVerdict, 6> kVerdicts = {
    MutationVerdict::NotApplicable, MutationVerdict::ControlFails, MutationVerdict::NoEffect,
    MutationVerdict::Caught,        MutationVerdict::Missed,       MutationVerdict::Error};

std::uint64_t nameHash(const char* s) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a 64
  for (; *s; ++s) {
    h ^= static_cast<unsigned char>(*s);
    h *= 1099511628211ull;
  }
  return h;
}

std::set<std::string> classSet(const json& j, const std::string& where, const char* key) {
  std::set<std::string> out;
  if (!j.contains(key)) return out;
  if (!j[key].is_array()) throw InputError(fmt::format("{}.{}: must be an array", where, key));
  for (const json& v : j[key]) {
    if (!v.is_string()) throw InputError(fmt::format("{}.{}: must hold strings", where, key));
    out.insert(v.get<std::string>());
  }
  return out;
}

std::string percent(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? std::string("-")
                    : fmt::format("{:.1f} %",
                                  100.0 * static_cast<double>(part) / static_cast<double>(whole));
}

}  // namespace

std::span<const MutationFault> mutationFaults() { return kFaults; }

const MutationFault& mutationFault(const std::string& name) {
  for (const MutationFault& f : kFaults)
    if (name == f.name) return f;
  std::vector<std::string> names;
  names.reserve(kFaults.size());
  for (const MutationFault& f : kFaults) names.emplace_back(f.name);
  throw InputError(
      fmt::format("--faults: unknown fault '{}' (valid: {})", name, fmt::join(names, ", ")));
}

std::string faultSetting(const MutationFault& fault, const MutationScene& scene, std::uint64_t seed,
                         std::uint64_t index) {
  const std::string name = fault.name;
  if (name == "light_scale") return "light_scale=1.01";
  if (name == "depth_bias") return scene.depth_format == "d16" ? "depth_bias=8" : "depth_bias=64";
  if (name == "texel_offset") return scene.textured ? "texel_offset=1" : "";
  if (name == "blend_factor") return scene.blended ? "blend_factor=one" : "";
  if (name == "depth_func") return scene.depth_tested ? "depth_func=inverted" : "";
  if (name == "stencil_op") return scene.stencil ? "stencil_op=shifted" : "";
  if (name == "blend_function") return scene.blend_function ? "blend_function=shifted" : "";
  if (name == "scissor_shift") return scene.scissor ? "scissor_shift=1" : "";
  if (name == "lod_shift") return scene.lod ? "lod_shift=1" : "";
  if (name == "lod_weight") return scene.lod_blend ? "lod_weight=inverted" : "";
  if (name == "shadow_shift") return scene.shadowed ? "shadow_shift=1" : "";
  if (name == "shadow_compare") return scene.shadowed ? "shadow_compare=inverted" : "";
  if (name == "shadow_bias") return scene.shadow_bias ? "shadow_bias=dropped" : "";
  // The candidates: visible segments, points, or (move_vertex) the other visible ids.
  std::vector<std::uint32_t> ids;
  auto in = [](const std::vector<std::uint32_t>& sorted, std::uint32_t id) {
    return std::binary_search(sorted.begin(), sorted.end(), id);
  };
  for (std::uint32_t id : scene.visible_ids) {
    const bool line = in(scene.line_ids, id);
    const bool point = in(scene.point_ids, id);
    if (name == "move_line_end" ? line
        : name == "move_point"  ? point
        : name == "move_vertex" ? !line && !point
                                : true)
      ids.push_back(id);
  }
  if (ids.empty()) return "";
  // The same primitive on every run: a stream seeded by (seed, index, fault).
  RandomStream stream(RandomStream::mix(seed) ^ RandomStream::mix(index + 0x632be59bd9b4e019ull) ^
                      nameHash(fault.name));
  const auto pick =
      static_cast<std::size_t>(stream.integer(0, static_cast<std::int64_t>(ids.size()) - 1));
  return fmt::format("{}={}", name, ids[pick]);
}

const char* toString(MutationVerdict v) {
  switch (v) {
    case MutationVerdict::NotApplicable:
      return "not_applicable";
    case MutationVerdict::ControlFails:
      return "control_fails";
    case MutationVerdict::NoEffect:
      return "no_effect";
    case MutationVerdict::Caught:
      return "caught";
    case MutationVerdict::Missed:
      return "missed";
    case MutationVerdict::Error:
      return "error";
  }
  return "?";
}

MutationVerdict mutationVerdictFromString(const std::string& text) {
  for (MutationVerdict v : kVerdicts)
    if (text == toString(v)) return v;
  throw InputError(fmt::format("unknown mutation verdict \"{}\"", text));
}

Frame effectFrame(const Frame& clean, const Frame& faulted, const Frame& reference) {
  for (const Frame* f : {&faulted, &reference}) {
    if (f->width != clean.width || f->height != clean.height || f->samples != clean.samples)
      throw InputError(fmt::format("mutation study: frames of {}x{} ({} samples) and {}x{} ({})",
                                   clean.width, clean.height, clean.samples, f->width, f->height,
                                   f->samples));
  }
  Frame out = faulted;
  const std::size_t n = clean.pixelCount();
  // The fault's change of one value, less how far the clean driver already is from the
  // reference there: what is left shows against the reference whichever way the two go.
  // Anything not finite keeps the faulted value: a NaN the fault made must still count.
  auto net = [](float c, float f, float r) {
    const float m = std::fabs(c - r);
    const float d = f - c;
    if (!std::isfinite(m) || !std::isfinite(d)) return f;
    if (std::fabs(d) <= m) return c;
    return d > 0.0f ? f - m : f + m;
  };
  const bool sample_ref =
      clean.multisampled() && reference.sample_depth.size() == clean.sample_depth.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (reference.id[i] == clean.id[i]) {
      out.depth[i] = net(clean.depth[i], faulted.depth[i], reference.depth[i]);
      for (int c = 0; c < 4; ++c) {
        const std::size_t k = 4 * i + static_cast<std::size_t>(c);
        out.color[k] = net(clean.color[k], faulted.color[k], reference.color[k]);
      }
      if (sample_ref) {
        for (int s = 0; s < clean.samples; ++s) {
          const std::size_t k = clean.sampleIndex(s, i);
          out.sample_depth[k] =
              net(clean.sample_depth[k], faulted.sample_depth[k], reference.sample_depth[k]);
        }
      }
      continue;
    }
    out.depth[i] = clean.depth[i];
    for (int c = 0; c < 4; ++c) out.color[4 * i + c] = clean.color[4 * i + c];
    if (clean.multisampled()) {
      for (int s = 0; s < clean.samples; ++s)
        out.sample_depth[clean.sampleIndex(s, i)] = clean.sample_depth[clean.sampleIndex(s, i)];
    }
  }
  return out;
}

MutationVerdict judgeMutation(const std::string& cls, const std::set<std::string>& control_fails,
                              const std::set<std::string>& effect_fails,
                              const std::set<std::string>& detected_fails) {
  if (control_fails.contains(cls)) return MutationVerdict::ControlFails;
  if (!effect_fails.contains(cls)) return MutationVerdict::NoEffect;
  return detected_fails.contains(cls) ? MutationVerdict::Caught : MutationVerdict::Missed;
}

json toJson(const MutationResult& r) {
  return {{"fixture", r.fixture},
          {"fixture_file", r.fixture_file},
          {"backend", r.backend},
          {"fault", r.fault},
          {"setting", r.setting},
          {"verdict", toString(r.verdict)},
          {"control_fails", r.control_fails},
          {"effect_fails", r.effect_fails},
          {"detected_fails", r.detected_fails},
          {"note", r.note}};
}

MutationResult mutationResultFromJson(const json& j, const std::string& source) {
  if (!j.is_object()) throw InputError(fmt::format("{}: must be an object", source));
  auto text = [&](const char* key) {
    if (!j.contains(key) || !j[key].is_string())
      throw InputError(fmt::format("{}.{}: missing or not a string", source, key));
    return j[key].get<std::string>();
  };
  MutationResult r;
  r.fixture = text("fixture");
  r.fixture_file = text("fixture_file");
  r.backend = text("backend");
  r.fault = text("fault");
  r.setting = text("setting");
  r.verdict = mutationVerdictFromString(text("verdict"));
  r.control_fails = classSet(j, source, "control_fails");
  r.effect_fails = classSet(j, source, "effect_fails");
  r.detected_fails = classSet(j, source, "detected_fails");
  r.note = text("note");
  return r;
}

std::uint64_t MutationTally::counted() const {
  const auto at = [&](MutationVerdict v) {
    const auto it = verdicts.find(v);
    return it == verdicts.end() ? std::uint64_t{0} : it->second;
  };
  return at(MutationVerdict::Caught) + at(MutationVerdict::Missed);
}

double MutationTally::caughtFraction() const {
  const std::uint64_t n = counted();
  const auto it = verdicts.find(MutationVerdict::Caught);
  return n == 0 ? 1.0 : static_cast<double>(it == verdicts.end() ? 0 : it->second) / n;
}

MutationTallies tallyMutations(const std::vector<MutationResult>& results) {
  MutationTallies out;
  for (const MutationResult& r : results) {
    MutationTally& t = out[r.backend][r.fault];
    ++t.scenes;
    ++t.verdicts[r.verdict];
    if (r.verdict == MutationVerdict::Missed) t.missed.push_back(&r);
  }
  return out;
}

std::string mutationMarkdown(const MutationTallies& tallies, const std::string& command,
                             std::uint64_t scenes_run, std::uint64_t scenes_total, bool complete) {
  std::string md = "# Mutation study\n\n";
  md +=
      fmt::format("Command: `{}`\n\n{} of {} scenes done{}.\n\n", command, scenes_run, scenes_total,
                  complete ? "" : " (**incomplete**: run the same command again to continue)");
  md +=
      "A scene counts for a fault when the fault changes some pixel beyond its allowance in the "
      "fault's class (`compare CLEAN FAULTED --uncertainty REF` fails in that class) and the "
      "clean driver does not already fail there against the reference; it is caught when "
      "`compare REF FAULTED` fails in the fault's class (docs/campaigns.md).\n\n";
  for (const auto& [backend, faults] : tallies) {
    md += fmt::format("## `{}`\n\n", backend);
    md +=
        "| fault | class | scenes | not applicable | control fails | no effect beyond "
        "allowance | counted | caught | missed | error | caught in class |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const MutationFault& f : mutationFaults()) {
      const auto it = faults.find(f.name);
      if (it == faults.end()) continue;
      const MutationTally& t = it->second;
      auto n = [&](MutationVerdict v) {
        const auto k = t.verdicts.find(v);
        return k == t.verdicts.end() ? std::uint64_t{0} : k->second;
      };
      md +=
          fmt::format("| `{}` ({}) | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", f.name,
                      f.what, f.cls, t.scenes, n(MutationVerdict::NotApplicable),
                      n(MutationVerdict::ControlFails), n(MutationVerdict::NoEffect), t.counted(),
                      n(MutationVerdict::Caught), n(MutationVerdict::Missed),
                      n(MutationVerdict::Error), percent(n(MutationVerdict::Caught), t.counted()));
    }
    bool any_missed = false;
    for (const auto& [fault, t] : faults) {
      for (const MutationResult* r : t.missed) {
        if (!any_missed)
          md +=
              "\nMissed (the fault changed the driver's image beyond the "
              "allowance, the comparison with the reference did not fail in "
              "its class):\n\n";
        any_missed = true;
        md += fmt::format("- `{}` with `{}` ({}): {}\n", r->fixture, r->setting, r->fixture_file,
                          r->note);
      }
    }
    md += "\n";
  }
  return md;
}

json mutationJson(const MutationTallies& tallies, const std::vector<MutationResult>& all,
                  const std::string& command, const json& options, std::uint64_t scenes_run,
                  std::uint64_t scenes_total, bool complete) {
  json backends = json::object();
  for (const auto& [backend, faults] : tallies) {
    json jf = json::object();
    for (const auto& [fault, t] : faults) {
      json verdicts = json::object();
      for (MutationVerdict v : kVerdicts) {
        const auto it = t.verdicts.find(v);
        verdicts[toString(v)] = it == t.verdicts.end() ? 0 : it->second;
      }
      jf[fault] = {{"class", mutationFault(fault).cls},
                   {"scenes", t.scenes},
                   {"verdicts", verdicts},
                   {"counted", t.counted()},
                   {"caught_fraction", t.caughtFraction()}};
    }
    backends[backend] = jf;
  }
  json results = json::array();
  for (const MutationResult& r : all) results.push_back(toJson(r));
  return {{"format", "rastercheck-mutations/1"},
          {"command", command},
          {"options", options},
          {"complete", complete},
          {"scenes", {{"total", scenes_total}, {"run", scenes_run}}},
          {"backends", backends},
          {"results", results}};
}

}  // namespace rc
