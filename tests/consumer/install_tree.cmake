# cmake -DBUILD=<build dir> -DPREFIX=<dir> -P install_tree.cmake: a fresh install of the
# build into PREFIX (nothing left from an earlier one), then the layout the package promises.
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${PREFIX}
                RESULT_VARIABLE status OUTPUT_QUIET)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "cmake --install ${BUILD} --prefix ${PREFIX} failed: ${status}")
endif()
foreach(path bin/rastercheck libexec/rastercheck/rastercheck-core
             libexec/rastercheck/rastercheck-mesh-import
             include/rastercheck/fixtures/scene.h include/rastercheck/compare/compare.h
             share/rastercheck/fixtures/expectations.json
             share/rastercheck/fixtures/scenes/shading/blinn_phong_sphere.json)
  if(NOT EXISTS ${PREFIX}/${path})
    message(FATAL_ERROR "the installed tree lacks ${path}")
  endif()
endforeach()
file(GLOB_RECURSE configs ${PREFIX}/*rastercheckConfig.cmake)
file(GLOB_RECURSE libraries ${PREFIX}/*librastercheck_*.a)
list(LENGTH libraries count)
if(NOT configs OR NOT count EQUAL 5)
  message(FATAL_ERROR "expected rastercheckConfig.cmake and 5 libraries, found: ${configs} ${libraries}")
endif()
# Every exported module carries the C++ standard its headers need (a consumer that sets
# none still compiles them: package.consumer_build).
file(GLOB_RECURSE target_files ${PREFIX}/*rastercheckTargets.cmake)
file(READ "${target_files}" targets)
string(REGEX MATCHALL "INTERFACE_COMPILE_FEATURES \"cxx_std_20\"" features "${targets}")
list(LENGTH features feature_count)
if(NOT feature_count EQUAL 5)
  message(FATAL_ERROR "expected cxx_std_20 on the 5 exported targets, found ${feature_count} in ${target_files}")
endif()
