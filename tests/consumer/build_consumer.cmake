# cmake -DSOURCE=... -DBINARY=... -DPREFIX=... -DGENERATOR=... -DCXX=... [-DLAUNCHER=ccache]
#   -P build_consumer.cmake: configures the consumer project against the package installed
# in PREFIX only (CMAKE_PREFIX_PATH; the build tree is not searched) and builds it.
file(REMOVE_RECURSE ${BINARY})
set(args -S ${SOURCE} -B ${BINARY} -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release
         -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${PREFIX}
         -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
if(LAUNCHER)
  list(APPEND args -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
foreach(step "${args}" "--build;${BINARY}")
  execute_process(COMMAND ${CMAKE_COMMAND} ${step} RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "cmake ${step} failed: ${status}")
  endif()
endforeach()
