# Faster loading of OpenImageIO: for the image module (fixtures/image_io.h), which a
# process loads the first time it touches an image, and for test programs that call
# OpenImageIO themselves.
#
# Debian's OpenImageIO pulls in ~260 shared libraries (OpenVDB, GDAL, ffmpeg, ...). The
# dynamic loader resolves every symbol relocation by walking the global search list in
# order, and the list is breadth-first from the executable, so a heavy C++ library deep in
# it (libopenvdb: ~57,000 self-references at position ~35; GDAL, Xerces, GEOS further
# down) pays that walk tens of thousands of times: ~150 ms of the ~200 ms every
# `rastercheck` process spent before main (perf: 70% in do_lookup_x). Naming the
# libraries with the most symbol relocations first in the executable's DT_NEEDED list
# moves them to the front of the search list and cuts start-up by ~60 ms
# (docs/performance.md). Nothing new is loaded: each of them is already a dependency.
#
# Effect on binding: a symbol defined in several loaded libraries binds to the first in
# the list. Checked with LD_BIND_NOW=1 LD_DEBUG=bindings: the bindings that change are
# vague-linkage copies (inline functions and template instances, e.g. std::vector
# members) defined identically in several libraries.
option(RASTERCHECK_STARTUP_ORDER "Put heavily relocated shared libraries first in the search list" ON)

# The same holds for a module opened with dlopen: its own search list (breadth-first from
# the module) follows the global one, so its DT_NEEDED order decides the walk.
#
# rc_startup_order(TARGET LIB...): for an executable or module TARGET linked with the shared
# libraries LIB (full paths), lists the run-time dependencies of LIB with >= 1000 symbol
# relocations first in TARGET's DT_NEEDED entries.
function(rc_startup_order target)
  if(NOT RASTERCHECK_STARTUP_ORDER OR NOT CMAKE_SYSTEM_NAME STREQUAL "Linux" OR NOT CMAKE_READELF)
    return()
  endif()
  set(seeds "${ARGN}")
  if(NOT DEFINED RC_STARTUP_ORDER_LIBS OR NOT "${RC_STARTUP_ORDER_SEEDS}" STREQUAL "${seeds}")
    execute_process(
      COMMAND bash "${PROJECT_SOURCE_DIR}/cmake/startup_order.sh" "${CMAKE_READELF}" 1000 ${seeds}
      OUTPUT_VARIABLE libs
      RESULT_VARIABLE status
      OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT status EQUAL 0)
      set(libs "")
    endif()
    string(REPLACE "\n" ";" libs "${libs}")
    set(RC_STARTUP_ORDER_LIBS "${libs}" CACHE INTERNAL "Libraries listed first (StartupOrder.cmake)")
    set(RC_STARTUP_ORDER_SEEDS "${seeds}" CACHE INTERNAL "Inputs of RC_STARTUP_ORDER_LIBS")
    list(LENGTH libs count)
    message(STATUS "Start-up order: ${count} heavily relocated libraries listed first")
  endif()
  if(RC_STARTUP_ORDER_LIBS)
    # Link options precede the objects and libraries on the link line, so these become
    # the first DT_NEEDED entries; --no-as-needed keeps them although nothing of ours
    # references them directly.
    target_link_options(${target} PRIVATE "LINKER:--push-state,--no-as-needed"
                        ${RC_STARTUP_ORDER_LIBS} "LINKER:--pop-state")
  endif()
endfunction()
