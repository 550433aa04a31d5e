// State and feature probes: see probes.h.
#include "debug/probes.h"

#include <algorithm>
#include <array>

#include <fmt/format.h>

namespace rc {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// One state key: its default (docs/fixture-format.md) and the alternative a default value
// is probed at (null: no alternative that could matter without changing what is drawn,
// e.g. culling, or blending an opaque scene). front_face is not probed: without culling
// it changes nothing, with culling flipping it draws the other triangles, which says
// nothing about the failure (the cull probe covers culling).
struct StateKey {
  const char* key;
  json value_default;
  json alternative;
  enum class Needs { Nothing, Lights, PointLights, Texture } needs;
};

const std::array<StateKey, 11>& stateKeys() {
  using N = StateKey::Needs;
  static const std::array<StateKey, 11> keys = {{
      {"shading", "phong", "gouraud", N::Lights},
      {"specular_model", "blinn-phong", "phong", N::Lights},
      {"attenuation", "none", "inverse", N::PointLights},
      {"depth_test", true, false, N::Nothing},
      {"depth_format", "d24", "d32f", N::Nothing},
      {"color_format", "rgba32f", "rgba8", N::Nothing},
      {"cull", "none", nullptr, N::Nothing},
      {"blend", "none", nullptr, N::Nothing},
      {"visibility", "zbuffer", "painter", N::Nothing},
      {"texture_filter", "nearest", "linear", N::Texture},
      {"texture_wrap", "repeat", "clamp", N::Texture},
  }};
  return keys;
}

std::string valueText(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

bool hasLights(const json& f, bool point_only) {
  if (!f.contains("lights") || !f["lights"].is_array()) return false;
  return std::any_of(f["lights"].begin(), f["lights"].end(), [&](const json& l) {
    return !point_only || (l.is_object() && l.value("type", std::string()) == "point");
  });
}

// Calls fn(material) for every material object the document defines.
template <class Fn>
void forEachMaterial(json& f, Fn fn) {
  if (!f.contains("materials") || !f["materials"].is_object()) return;
  for (auto& [name, m] : f["materials"].items())
    if (m.is_object()) fn(m);
}

bool anyMaterial(const json& f, bool (*test)(const json&)) {
  if (!f.contains("materials") || !f["materials"].is_object()) return false;
  const json& materials = f["materials"];
  return std::any_of(materials.begin(), materials.end(),
                     [&](const json& m) { return m.is_object() && test(m); });
}

bool textured(const json& m) { return m.contains("texture"); }
bool transparent(const json& m) {
  return m.contains("opacity") && m["opacity"].is_number() && m["opacity"].get<double>() < 1.0;
}

}  // namespace

bool probeMatters(const std::string& key, const std::string& cls) {
  static const std::vector<std::string> shading = {
      "shading",        "specular_model", "attenuation", "color_format", "blend",
      "texture_filter", "texture_wrap",   "texture",     "transparency", "lights"};
  static const std::vector<std::string> coverage = {"depth_test", "depth_format", "cull",
                                                    "blend",      "visibility",   "transparency"};
  if (cls.empty()) return true;
  const auto& keys = cls == "shading" ? shading : coverage;
  return std::find(keys.begin(), keys.end(), key) != keys.end();
}

std::vector<Probe> makeProbes(const json& fixture, const std::string& cls) {
  const std::string name = fixture.value("name", std::string("fixture"));
  std::vector<Probe> out;
  auto add = [&](std::string key, std::string involves, std::string change, json f) {
    if (!key.empty() && !probeMatters(key, cls)) return;
    f["name"] = fmt::format("{}/probe/{}", name, key.empty() ? "unchanged" : key);
    out.push_back({std::move(key), std::move(involves), std::move(change), std::move(f)});
  };
  add("", "", "unchanged", fixture);

  const json state =
      fixture.contains("state") && fixture["state"].is_object() ? fixture["state"] : json::object();
  const bool lights = hasLights(fixture, false);
  const bool point_lights = hasLights(fixture, true);
  const bool texture = anyMaterial(fixture, textured);
  for (const StateKey& k : stateKeys()) {
    using N = StateKey::Needs;
    if ((k.needs == N::Lights && !lights) || (k.needs == N::PointLights && !point_lights) ||
        (k.needs == N::Texture && !texture))
      continue;
    const json current = state.contains(k.key) ? state[k.key] : k.value_default;
    const json probed = current == k.value_default ? k.alternative : k.value_default;
    if (probed.is_null()) continue;
    json f = fixture;
    f["state"][k.key] = probed;
    add(k.key, fmt::format("{}={}", k.key, valueText(current)),
        fmt::format("{} {} -> {}", k.key, valueText(current), valueText(probed)), std::move(f));
  }
  if (texture) {
    json f = fixture;
    forEachMaterial(f, [](json& m) { m.erase("texture"); });
    add("texture", "texture", "textures removed", std::move(f));
  }
  const bool blending = state.contains("blend") && state["blend"] == "alpha";
  if (blending && anyMaterial(fixture, transparent)) {
    json f = fixture;
    forEachMaterial(f, [](json& m) { m["opacity"] = 1.0; });
    add("transparency", "transparency", "every opacity 1", std::move(f));
  }
  if (lights) {
    json f = fixture;
    f["lights"] = json::array();
    add("lights", "lights", "lights removed", std::move(f));
  }
  return out;
}

std::vector<std::string> involvedIn(const std::vector<Probe>& probes,
                                    const std::vector<std::optional<bool>>& still_fails) {
  std::vector<std::string> out;
  if (probes.empty() || still_fails.empty() || still_fails[0] != true) return out;
  for (std::size_t i = 1; i < probes.size() && i < still_fails.size(); ++i)
    if (still_fails[i] == false) out.push_back(probes[i].involves);
  std::sort(out.begin(), out.end());
  return out;
}

void absolutizePaths(json& fixture, const fs::path& base) {
  auto fix = [&](json& v) {
    if (!v.is_string()) return;
    const fs::path p = v.get<std::string>();
    if (p.is_relative()) v = (base / p).lexically_normal().string();
  };
  forEachMaterial(fixture, [&](json& m) {
    if (m.contains("texture")) fix(m["texture"]);
  });
  if (fixture.contains("objects") && fixture["objects"].is_array())
    for (json& o : fixture["objects"])
      if (o.is_object() && o.contains("mesh") && o["mesh"].is_object() &&
          o["mesh"].contains("file"))
        fix(o["mesh"]["file"]);
}

}  // namespace rc
