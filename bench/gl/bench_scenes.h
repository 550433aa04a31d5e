// Scenes of the GL and frame-file benchmarks: the 1920x1080 scene whose stages are timed,
// and the reference benchmark's scenes (bench/reference/bench_reference.cpp: 100k tiny
// triangles, 8 full-screen layers), so that bench/run.sh can put the reference and the
// GL drivers side by side as ratios on the same work.
#pragma once

#include "fixtures/scene.h"

namespace rc::bench {

// A lit sphere (64 x 32 segments) over a ground quad, perspective, Phong shading, two
// lights: the kind of scene the conformance suite renders, at 1920x1080.
Scene sphere1080p(ColorFormat color);

// The reference benchmark's scenes at 1024x1024, built from the same test builders
// (tests/reference/test_scenes.h) with the same parameters:
// 100k right triangles with 2-pixel legs at random positions, flat, one material.
Scene smallTriangles();
// The same triangles as one grid mesh (shared vertices, row order).
Scene smallTriangleMesh();
// 8 full-screen rectangles back to front, one point light, Blinn-Phong, shininess 32.
Scene layers(Shading shading);
// 20k segments (random ends, 2 to 60 px long, every third 3 px wide) and 20k points of size
// 3, Gouraud with one point light, depth tested: lines and points at scale.
Scene linesAndPoints();
// A teapot on a floor through a shadow map (test::shadowScene at the reference's size).
Scene shadowMap();

}  // namespace rc::bench
