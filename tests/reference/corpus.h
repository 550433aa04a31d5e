// The determinism corpus: frames of the feature scenes (built in code) and of fixture
// files (through the loader, so that TRS transforms, generators, imported meshes and
// computed normals are covered too), each under several option sets, as one hash per
// frame. The dump tools list it from builds at -O0 and -O2 (tests/reference/
// CMakeLists.txt) and test_determinism compares them with its own build; `reference_dump
// --bench fixtures/scenes` is the before/after check for optimisations (docs/reference.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fixtures/frame.h"

namespace rc::test {

// Fixture files under `dir` (recursively, *.json), sorted: the catalog part of the corpus.
std::vector<std::filesystem::path> fixtureFiles(const std::filesystem::path& dir);

// Renders the feature scenes, then every fixture file in order (loaded with loadScene),
// then, when with_bench is set, the benchmark scenes, each with every option set (default;
// subpixel 4; subpixel 12 with painter's forced; default without uncertainty channels),
// and calls sink(name, frame) for each frame in that order.
void renderCorpus(const std::vector<std::filesystem::path>& fixtures, bool with_bench,
                  const std::function<void(const std::string&, const Frame&)>& sink);

// FNV-1a (64-bit) of a frame's frameBytes(): equal frames hash equal, and a one-bit
// difference changes the hash (the chance that two different frames collide is 2^-64).
std::uint64_t frameHash(const Frame& frame);

// One line "<16 hex digits> <name>\n" per corpus frame, in renderCorpus() order: what the
// dump tools print and test_determinism compares.
std::string corpusHashes(const std::vector<std::filesystem::path>& fixtures, bool with_bench);

}  // namespace rc::test
