# Where `cmake --install` puts things, and rc_package_module(), which each module library
# calls to join the exported package. The package itself (export set, config file, the
# command, the catalog, CPack) is cmake/Package.cmake, read after every module exists.
#
# Installed layout, every path relative to the prefix so that the tree can be moved
# (`cmake --install --prefix`, the Debian package under /usr):
#   include/rastercheck/<module>/*.h     headers, included as <rastercheck/fixtures/scene.h>
#   lib/librastercheck_<module>.a        the module libraries (static)
#   lib/cmake/rastercheck/               rastercheckConfig.cmake: rastercheck::<module>
#   bin/rastercheck                      the command (a small launcher)
#   libexec/rastercheck/                 rastercheck-core and rastercheck-mesh-import
#   share/rastercheck/fixtures/          the catalog (scenes/) and expectations.json
include(GNUInstallDirs)

set(RC_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/rastercheck)
set(RC_INSTALL_HELPERDIR ${CMAKE_INSTALL_LIBEXECDIR}/rastercheck)
set(RC_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/rastercheck)

# The headers include one another by module path ("fixtures/scene.h"), the form the
# source tree uses, so the package puts include/rastercheck on the path as well as include/.
# The build tree offers the installed form too (<rastercheck/fixtures/scene.h> through
# links in the build folder), so that a project that adds this tree as a subdirectory
# includes the headers as one that uses the installed package does.
set(RC_BUILD_INCLUDEDIR ${PROJECT_BINARY_DIR}/include)
set(RC_MODULES fixtures reference gl_backend compare debug)
file(MAKE_DIRECTORY ${RC_BUILD_INCLUDEDIR}/rastercheck)
foreach(module IN LISTS RC_MODULES)
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${module} ${RC_BUILD_INCLUDEDIR}/rastercheck/${module}
       SYMBOLIC)
endforeach()

# rc_package_module(TARGET MODULE): TARGET is the library of the module folder MODULE. Sets
# its include directories (source tree when building, include/ when installed) and its C++
# standard as a usage requirement, names it
# rastercheck::MODULE (an alias in the build tree, the exported name when installed) and
# installs it with the headers of its folder.
function(rc_package_module target module)
  if(NOT module IN_LIST RC_MODULES)
    message(FATAL_ERROR "rc_package_module: ${module} is not one of the modules: ${RC_MODULES}")
  endif()
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<BUILD_INTERFACE:${RC_BUILD_INCLUDEDIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/rastercheck>)
  # The headers need C++20 (defaulted operator==, std::span): a consumer that links the
  # target gets the requirement with it, whatever standard its own project sets.
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module} OUTPUT_NAME rastercheck_${module})
  add_library(rastercheck::${module} ALIAS ${target})
  install(TARGETS ${target} EXPORT rastercheckTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/rastercheck/${module}
          FILES_MATCHING PATTERN "*.h"
          PATTERN "*_internal.h" EXCLUDE  # shared between a module's own files, not an API
          PATTERN "scenes" EXCLUDE)
endfunction()
