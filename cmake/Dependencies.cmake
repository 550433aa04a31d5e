# Finds every third-party dependency once, as imported targets the modules link to.
# Versions measured on Debian 12 (see ../shared/DESIGN.md): CONFIG packages for glm,
# assimp, nlohmann_json, CLI11 and fmt; pkg-config for OpenImageIO (its CMake config
# names a missing opencv include dir) and OSMesa.
find_package(glm CONFIG REQUIRED)
find_package(assimp CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(fmt CONFIG REQUIRED)
find_package(Threads REQUIRED)
find_package(ZLIB REQUIRED)  # crc32/adler32 for the PNGs of generated random scenes
find_package(OpenGL REQUIRED COMPONENTS EGL OpenGL)
find_package(PkgConfig REQUIRED)
pkg_check_modules(OIIO REQUIRED IMPORTED_TARGET OpenImageIO)
pkg_check_modules(OSMESA IMPORTED_TARGET osmesa)
find_package(VulkanHeaders CONFIG QUIET)  # optional: zink's device query (gl_backend/)
if(RASTERCHECK_BUILD_TESTS)
  find_package(GTest REQUIRED)
  include(GoogleTest)
endif()
if(RASTERCHECK_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
