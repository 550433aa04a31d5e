// State and feature probes: which parts of a failing fixture its failure needs. A probe
// is the fixture with one thing changed: a state key set to another value, or the
// textures, the transparency or the lights taken away. When the fixture fails and a probe
// of it passes, what the probe changed is involved in the failure. The probes work on
// fixture JSON (the file as `reduce` writes it), so this needs no loader and no renderer;
// rendering and comparing them is the caller's (`campaign` runs them through `run`).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rc {

struct Probe {
  std::string key;       // e.g. "depth_format", "texture"; empty for the unchanged fixture
  std::string involves;  // what the failure needs when this probe passes: "depth_format=d16"
  std::string change;    // for people: "depth_format d16 -> d24", "textures removed"
  nlohmann::json fixture;
};

// The probes of `fixture` for a failure in class `cls` (visibility, depth or shading; empty:
// every probe), named "<its name>/probe/<key>" so that one `run` can hold them all. Only
// what can change that class is probed (probeMatters): for shading the lighting keys,
// color_format, blending, textures and lights; for visibility and depth the depth test and
// format, culling, blending and the visibility mode. Elsewhere a probe would only move
// pixels around and make a fragile failure vanish by accident. The first is the fixture itself,
// unchanged (key empty), which says whether it still fails. A state key at a non-default value is
// probed at its default; a key at its default is probed at one alternative where that can matter
// (nearest -> linear, repeat -> clamp, depth test on -> off, d24 -> d32f, rgba32f -> rgba8, zbuffer
// -> painter, phong -> gouraud, blinn-phong -> phong, no attenuation -> 1/r); keys that cannot
// matter (texture keys without a texture, lighting keys without lights) and front_face are not
// probed. A missing state key is its default (docs/fixture-format.md).
std::vector<Probe> makeProbes(const nlohmann::json& fixture, const std::string& cls = "");

// Whether the probe of `key` (a state key, "texture", "transparency" or "lights") can
// tell something about a failure in class `cls`.
bool probeMatters(const std::string& key, const std::string& cls);

// What a failure needs, from whether each probe still fails in the failure's class
// (nullopt: it could not be rendered or compared). Empty when the unchanged fixture does
// not fail (probes[0]): then nothing can be concluded. Sorted.
std::vector<std::string> involvedIn(const std::vector<Probe>& probes,
                                    const std::vector<std::optional<bool>>& still_fails);

// Makes the relative file paths of a fixture document (material textures, mesh files)
// absolute against `base` (the folder of the file it was read from), so that the document
// can be written in another folder.
void absolutizePaths(nlohmann::json& fixture, const std::filesystem::path& base);

}  // namespace rc
