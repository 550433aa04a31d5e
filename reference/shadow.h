// Shadow lookups (materials' `shadow`, docs/reference.md "Shadow maps"): GL's depth
// comparison of a sampler2DShadow with GL_TEXTURE_COMPARE_MODE, clamp to edge, evaluated in
// double on the reference's own map, and the range of results another conforming
// implementation may give (docs/tolerances.md "Shadow maps").
#pragma once

#include <glm/glm.hpp>

#include "fixtures/scene.h"

namespace rc::ref {

// The map coordinates of world point p: (s, t) in [0, 1] across the map, r the window depth
// of the map's pass less the bias (clamped to [0, 1] for fixed-point maps, as GL clamps
// D_ref), and whether the point lies in front of the map's camera (w > 0; behind it the
// lookup is not made and the light is not shadowed).
struct ShadowCoord {
  double s = 0.0;
  double t = 0.0;
  double r = 0.0;
  bool in_front = false;
};
ShadowCoord shadowCoord(const ShadowLookup& lookup, const glm::dvec3& p);

// GL's result of the lookup at world point p: 1 lit, 0 shadowed; linear filtering weighs
// the 2x2 comparisons bilinearly (GL leaves the weights to the implementation; these are the
// reference's). 1 where the material has no bound map.
double shadowFactor(const ShadowLookup& lookup, const glm::dvec3& p);

// The results a conforming implementation may give at p: every texel its (s, t) may select
// when they move by up to (ds, dt) texels, each compared with r moved by up to dr, against
// the range its stored depth may take (ShadowMapData::lo, hi); linear filtering may weigh
// the comparisons of its footprint any way. [lo, hi] contains shadowFactor(lookup, p).
struct ShadowRange {
  double lo = 1.0;
  double hi = 1.0;
  int i = -1;  // the texel the lookup reads (nearest) or its footprint's lower-left (linear)
  int j = -1;
};
ShadowRange shadowRange(const ShadowLookup& lookup, const glm::dvec3& p, double ds, double dt,
                        double dr);

}  // namespace rc::ref
