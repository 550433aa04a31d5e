// The entry points the fuzzers drive (scripts/fuzz.sh) and the regression test replays:
// any bytes as a fixture file, as a mesh file, as a texture image. Each returns normally
// when the input is accepted or refused with one InputError, and aborts (a finding) on
// anything else: another exception, or a refusal whose message is not one safe line.
// Crashes and sanitizer reports are findings by themselves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace rc::fuzz {

// The bytes as fixture JSON, loaded as if the file sat in tests/fixtures/data (so its
// meshes/ and textures/ resolve); the scene's resource estimate is computed too.
void loadFixtureBytes(const std::uint8_t* data, std::size_t size);

// The first byte picks the format (an index into the extensions below), the rest is the
// file, imported with its materials and textures.
void importMeshBytes(const std::uint8_t* data, std::size_t size);
inline constexpr const char* kMeshExtensions[] = {"obj", "ply", "stl", "off", "gltf", "glb",
                                                  "3ds", "dae", "fbx", "x",   "md2",  "ase"};

// The same input as importMeshBytes, with the Assimp side (mesh_import_assimp.h) run in
// this process instead of the importer child, so that libFuzzer sees its coverage: the
// checks before Assimp, Assimp, the node walk and materials, the stream written and read
// back (mesh_import.cpp's decoder), the textures decoded. Only the posix_spawn and the
// pipe are left out. ASE files are skipped: Assimp 5.2's ASE reader segfaults on
// malformed ones (docs/reliability.md, finding 4), which the child contains and which
// would stop in-process fuzzing at once. Defined in fuzz_mesh.cpp (the fuzz build only:
// it links Assimp into the fuzzer).
void importMeshBytesInProcess(const std::uint8_t* data, std::size_t size);

// For the entries defined elsewhere: aborts unless the refusal's message is one safe
// line; a file of this process's own to write an input to.
void checkRefusalMessage(const char* what);
std::string scratchFile(const std::string& name);

// The first byte picks the format hint, the rest is the image, decoded from memory.
void decodeTextureBytes(const std::uint8_t* data, std::size_t size);
inline constexpr const char* kTextureExtensions[] = {"png", "jpg", "bmp", "tga", "exr",
                                                     "hdr", "tif", "gif", "ppm", ""};

}  // namespace rc::fuzz
