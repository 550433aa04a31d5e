# rc_unity_build(TARGET...): compile a target's files as one translation unit per 8
# (CMake's unity build). Most of a file's compile time here is the headers it shares with
# its neighbours (nlohmann-json, CLI11, fmt, GLM, the standard library) and the templates
# they instantiate again in every file; a batch parses and instantiates them once. A clean
# build with every target's files compiled one by one took 1,225 s of CPU on 2 cores
# (docs/reliability.md, "CI"). A file whose file-local names clash with a neighbour's is
# kept out with SKIP_UNITY_BUILD_INCLUSION where its target is defined.
# Not for the reference renderer (rc_reference, 9 files, 32 s): what GCC inlines across its
# files is tuned against bench/reference, and a batch would change it.
# RASTERCHECK_UNITY_BUILD=OFF compiles file by file: compile_commands.json then names each
# source file (clang-tidy, clangd); the dev preset sets it.
option(RASTERCHECK_UNITY_BUILD "Compile targets as unity batches of 8 files" ON)
function(rc_unity_build)
  if(NOT RASTERCHECK_UNITY_BUILD)
    return()
  endif()
  foreach(target IN LISTS ARGN)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endforeach()
endfunction()
