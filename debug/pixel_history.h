// Pixel history, the library side of `rastercheck explain` (docs/explain.md): the
// reference's history of one pixel, like RenderDoc's pixel history: every fragment that
// reached it in draw order with its depth test and every term and factor of its colour
// (as the reference's own shading code computed them while tracing, reference/shading.h),
// what the reference stored there in the end with its uncertainty channels, and what a
// backend's frame has there with the comparator's class and per-pixel verdict. The JSON
// document is built first and the text story is told from it, so the two cannot disagree.
// It renders nothing but the trace: frames come from the caller (app/ renders GL in a
// child process).
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "compare/tolerances.h"
#include "fixtures/frame.h"
#include "fixtures/scene.h"
#include "reference/reference_renderer.h"

namespace rc {

inline constexpr const char* kExplainFormat = "rastercheck-explain/1";

struct PixelQuery {
  std::string fixture_file;    // as the user named it (the document's "fixture_file")
  std::string reference_spec;  // "ref", "ref:painter", ...: the reference whose history it is
  ReferenceOptions options;    // that SPEC's options
  int x = 0;                   // image coordinates (origin top-left, y down)
  int y = 0;
  bool abuffer = false;  // add the A-buffer's sorted list of blended fragments ("abuffer")
};

// The document of docs/explain.md without "backends" (an empty object): the trace of the
// pixel, and from `frame` (the reference's render of `scene` with query.options) its
// final values and uncertainty channels. Throws InputError when the pixel is outside the
// image.
nlohmann::ordered_json pixelHistory(const Scene& scene, const PixelQuery& query,
                                    const Frame& frame);

// The document's "backends.SPEC" entry: what `frame` (rendered by `spec`) has at pixel
// index i, and the comparator's class and per-pixel verdicts there against `reference`
// (its uncertainty frame too) under `tolerances` (compare/pair_tolerances.h), with the
// whole pair's status.
nlohmann::ordered_json backendPixel(const std::string& spec, const Frame& reference,
                                    const Frame& frame, const Tolerances& tolerances,
                                    std::size_t i);

// The document told as text, for people.
// A multi-pass fixture: the texels of the driver's shadow maps (its pass frames) that the
// reference's final fragment at the pixel looked up (pixelHistory()'s shading.lights[i].
// shadow), beside the reference's stored depth there: [{light, map, texel, reference,
// driver}], empty where no lookup was made.
nlohmann::ordered_json backendShadowTexels(const nlohmann::ordered_json& doc, const Frame& frame);
std::string pixelStory(const nlohmann::ordered_json& doc);

}  // namespace rc
