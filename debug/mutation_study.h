// The mutation study (`rastercheck campaign --mutations`, docs/campaigns.md): test-only GL
// faults (gl_backend/gl_testing.h) injected into random scenes, and per fault the fraction
// caught in the fault's class among the scenes where the fault changes some pixel beyond
// its allowance. This file holds the faults, how each is set for one scene, the verdict of
// one (scene, fault) from three comparisons, the tallies and the report; rendering and
// comparing is the caller's.
//
// Definitions, per scene, backend and fault (frames: REF the reference, CLEAN the driver
// without fault, FAULTED the driver with it; "fails in C" = that class's verdict is fail):
//   control  = compare(REF, CLEAN)                      (what the harness sees without fault)
//   effect   = compare(CLEAN, FAULTED, uncertainty REF) (what the fault did to the driver)
//   detected = compare(REF, FAULTED)                    (what the harness sees with it)
// `effect` sees FAULTED through effectFrame(): only at the pixels a comparison with REF
// judges in depth and shading (REF shows the primitive CLEAN shows), and there each value's
// change less the clean driver's own distance from REF (what then exceeds the allowance
// shows against REF whichever way the clean driver deviates).
// The fault changes some pixel beyond its allowance when `effect` fails in the fault's
// class; the scene counts for that fault only then, and only when `control` does not fail
// in that class (else a failure would prove nothing). It is caught when `detected` fails
// in the fault's class.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fixtures/frame.h"

namespace rc {

struct MutationFault {
  const char* name;  // the RASTERCHECK_GL_FAULT name
  const char* cls;   // the class it must be caught in
  const char* what;  // for people
};

// light_scale (shading), depth_bias (depth), drop_primitive and move_vertex (visibility),
// texel_offset and blend_factor (shading); the fragment operations' depth_func (visibility),
// stencil_op (depth: the stencil buffer is compared in that class), blend_function
// (shading) and scissor_shift (visibility); lod_shift (shading) for textures sampled with a
// level of detail, lod_weight (shading) for textures blended between two mip levels;
// move_line_end and move_point (visibility) for line and point primitives; shadow_shift,
// shadow_compare and shadow_bias (shading) for shadow lookups (shadow_bias where one has a
// bias).
std::span<const MutationFault> mutationFaults();
// Throws InputError naming the valid names.
const MutationFault& mutationFault(const std::string& name);

// What the scene offers a fault, read from its clean driver frame and its fixture.
struct MutationScene {
  std::vector<std::uint32_t> visible_ids;  // primitive ids the clean frame shows, ascending
  std::string depth_format = "d24";        // d16, d24 or d32f
  bool textured = false;                   // some drawn material has a texture
  bool blended = false;                    // blend alpha with a material of opacity < 1
  bool depth_tested = false;               // some pass tests depth (a function other than ALWAYS)
  bool stencil = false;                    // some pass has a stencil test
  bool blend_function = false;             // some pass blends with the object form of blend
  bool scissor = false;                    // some pass has a scissor box
  bool lod = false;  // textured, sampled with a level of detail (fixtures/scene.h lodSampling())
  bool lod_blend = false;    // textured with a *_mipmap_linear min filter (two levels blended)
  bool shadowed = false;     // a drawn material's shadow lookup darkens some light
  bool shadow_bias = false;  // and one of those lookups has a bias
  // Primitive ids of line segments and of points (line and point primitives; triangles in
  // polygon mode line or point are triangles), ascending: move_line_end and move_point pick
  // from the visible ones, move_vertex from the visible others.
  std::vector<std::uint32_t> line_ids;
  std::vector<std::uint32_t> point_ids;
};

// The RASTERCHECK_GL_FAULT value of `fault` for scene `index` of `seed`, e.g.
// "drop_primitive=17"; empty when the fault cannot change the scene (no texture, no
// blending, nothing visible). A primitive is drawn from the visible ones by a hash of
// (seed, index, fault), the same on every run. depth_bias is 4 x the format's default
// depth fail threshold (8 d16 steps, 64 d24 or d32f steps); light_scale is 1.01 (1 %
// brighter); texel_offset is 1 texel; blend_factor is `one` (GL_ONE for GL_SRC_ALPHA).
std::string faultSetting(const MutationFault& fault, const MutationScene& scene, std::uint64_t seed,
                         std::uint64_t index);

enum class MutationVerdict {
  NotApplicable,  // faultSetting gave nothing
  ControlFails,   // the clean driver already fails in the class: not counted
  NoEffect,       // the fault changed nothing beyond the allowance in its class: not counted
  Caught,
  Missed,
  Error,  // a render or comparison could not be done
};
const char* toString(MutationVerdict v);
MutationVerdict mutationVerdictFromString(const std::string& text);  // throws InputError

// The faulted frame as the effect comparison sees it: at every pixel where the reference
// shows another primitive (or the background) than the clean driver frame, depth and
// colour (and each sample's depth, multisampled) are the clean frame's. No comparison with
// the reference judges depth or colour at such a pixel (its visibility differs), so a
// fault's effect there can never be caught and must not count (seed 20261213 scene 3 on
// softpipe counted a 64-step d24 depth bias as an effect at one such edge pixel only).
// Ids are kept: visibility effects are judged everywhere, as the comparison with the
// reference judges visibility. Throws InputError when the three frames differ in size or
// sample count.
Frame effectFrame(const Frame& clean, const Frame& faulted, const Frame& reference);

// The verdict from the classes each comparison fails in.
MutationVerdict judgeMutation(const std::string& cls, const std::set<std::string>& control_fails,
                              const std::set<std::string>& effect_fails,
                              const std::set<std::string>& detected_fails);

// One (scene, backend, fault).
struct MutationResult {
  std::string fixture;
  std::string fixture_file;
  std::string backend;
  std::string fault;
  std::string setting;  // RASTERCHECK_GL_FAULT value (empty: not applicable)
  MutationVerdict verdict = MutationVerdict::NotApplicable;
  std::set<std::string> control_fails;
  std::set<std::string> effect_fails;
  std::set<std::string> detected_fails;
  std::string note;  // the error, or the detected comparison's description
};
nlohmann::json toJson(const MutationResult& r);
MutationResult mutationResultFromJson(const nlohmann::json& j, const std::string& source);

struct MutationTally {
  std::uint64_t scenes = 0;
  std::map<MutationVerdict, std::uint64_t> verdicts;
  std::vector<const MutationResult*> missed;
  std::uint64_t counted() const;  // caught + missed
  double caughtFraction() const;  // caught / counted (1 when none counted)
};
// Per backend, per fault (in mutationFaults() order).
using MutationTallies = std::map<std::string, std::map<std::string, MutationTally>>;
MutationTallies tallyMutations(const std::vector<MutationResult>& results);

// mutations.md and mutations.json of a study (`command` and `options` as the campaign's).
std::string mutationMarkdown(const MutationTallies& tallies, const std::string& command,
                             std::uint64_t scenes_run, std::uint64_t scenes_total, bool complete);
nlohmann::json mutationJson(const MutationTallies& tallies, const std::vector<MutationResult>& all,
                            const std::string& command, const nlohmann::json& options,
                            std::uint64_t scenes_run, std::uint64_t scenes_total, bool complete);

}  // namespace rc
