# cmake -DPREFIX=... -DDATADIR=share/rastercheck -DOUT=... -DVERSION=... -P installed_command.cmake:
# the installed `rastercheck` from PREFIX: the launcher starts the core in libexec, the
# default catalog is the installed one, and a `run` of a mesh fixture (the importer helper,
# a GL worker, the default expectations file) passes.
set(rc ${PREFIX}/bin/rastercheck)
function(run_rc)
  execute_process(COMMAND ${rc} ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "rastercheck ${ARGN}: exit ${status}\n${out}${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

run_rc(--version)
if(NOT out STREQUAL "rastercheck ${VERSION}\n")
  message(FATAL_ERROR "rastercheck --version printed '${out}'")
endif()
run_rc(list --json)
string(JSON count LENGTH "${out}")
string(JSON file GET "${out}" 0 file)
if(count LESS 50 OR NOT file MATCHES "^${PREFIX}/${DATADIR}/fixtures/scenes/")
  message(FATAL_ERROR "rastercheck list: ${count} fixtures, the first ${file}: not the installed catalog")
endif()
message(STATUS "list: ${count} fixtures from ${PREFIX}/${DATADIR}/fixtures/scenes")
file(REMOVE_RECURSE ${OUT})
run_rc(run ${PREFIX}/${DATADIR}/fixtures/scenes/real-mesh/ply_mesh.json
       --backends gl:egl:llvmpipe --out ${OUT})
message(STATUS "${out}")
