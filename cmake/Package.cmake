# The installed package (layout: cmake/Install.cmake): the export set of the module
# libraries and its config file, the rastercheck command with its helpers, the catalog,
# and the Debian package `cpack -G DEB` builds from the same tree (docs/install.md).
include(CMakePackageConfigHelpers)

# The static module libraries name the build's INTERFACE option targets on their link
# lines ($<LINK_ONLY:...>, which carries no compile options to a consumer); exported so
# that those names resolve.
install(TARGETS rc_warnings rc_strict_fp EXPORT rastercheckTargets)
install(EXPORT rastercheckTargets NAMESPACE rastercheck:: DESTINATION ${RC_INSTALL_CMAKEDIR})

if(TARGET Vulkan::Headers)
  set(RC_PACKAGE_NEEDS_VULKAN_HEADERS TRUE)
else()
  set(RC_PACKAGE_NEEDS_VULKAN_HEADERS FALSE)
endif()
configure_package_config_file(cmake/rastercheckConfig.cmake.in
  ${PROJECT_BINARY_DIR}/package/rastercheckConfig.cmake
  INSTALL_DESTINATION ${RC_INSTALL_CMAKEDIR}
  PATH_VARS RC_INSTALL_DATADIR RC_INSTALL_HELPERDIR)
# 0.x: a new minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/rastercheckConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/package/rastercheckConfig.cmake
              ${PROJECT_BINARY_DIR}/package/rastercheckConfigVersion.cmake
        DESTINATION ${RC_INSTALL_CMAKEDIR})

# The command: the launcher on PATH, the programs it starts beside each other
# (app/launcher.cpp and app/paths.cpp find them, and the catalog, relative to themselves).
install(TARGETS rastercheck RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS rastercheck-core rastercheck-mesh-import RUNTIME DESTINATION ${RC_INSTALL_HELPERDIR})
install(TARGETS rastercheck-image-io LIBRARY DESTINATION ${RC_INSTALL_HELPERDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/fixtures/scenes DESTINATION ${RC_INSTALL_DATADIR}/fixtures)
install(FILES ${PROJECT_SOURCE_DIR}/fixtures/expectations.json ${PROJECT_SOURCE_DIR}/fixtures/README.md
        DESTINATION ${RC_INSTALL_DATADIR}/fixtures)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# `cpack -G DEB` (from the build folder): one package with all of the above under /usr.
# Depends: the Debian 12 packages of cmake/Dependencies.cmake that running the command and
# building against the libraries need (the libraries are static, so a consumer links the
# -dev packages' libraries), and Mesa's EGL and Gallium drivers, which the GL backend opens
# at run time. OSMesa and zink's Vulkan driver are optional backends: Recommends.
set(CPACK_PACKAGE_NAME rastercheck)
set(CPACK_PACKAGE_VENDOR "rastercheck")
set(CPACK_PACKAGE_CONTACT "rastercheck maintainers <rastercheck@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Reference-vs-OpenGL rasterization validation harness (command, libraries, fixture catalog)")
set(CPACK_PACKAGE_DESCRIPTION
    "rastercheck renders fixture scenes with a scalar CPU reference rasterizer and with real OpenGL drivers (Mesa llvmpipe, softpipe, zink) and classifies every differing pixel as visibility, depth or shading. This package holds the rastercheck command, its static module libraries with headers and a CMake package (find_package(rastercheck)), and the fixture catalog.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES TRUE)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION devel)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libopenimageio-dev, libassimp-dev, libfmt-dev, libpugixml-dev, zlib1g-dev, libglm-dev, nlohmann-json3-dev, libegl-dev, pkg-config, libegl-mesa0, libgl1-mesa-dri")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libosmesa6, mesa-vulkan-drivers, assimp-testmodels")
# The exact shared-library versions the command was linked against, from dpkg-shlibdeps.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
include(CPack)
