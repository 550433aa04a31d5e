# rc_scene_builders: scenes built in code (tests/reference/test_scenes.h) for the reference
# tests, the determinism dump tools and the benchmarks of both renderers. Included from
# tests/reference and bench/reference, whichever comes first defines it.
if(NOT TARGET rc_scene_builders)
  add_library(rc_scene_builders STATIC ${PROJECT_SOURCE_DIR}/tests/reference/test_scenes.cpp)
  target_include_directories(rc_scene_builders PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(rc_scene_builders PUBLIC rc_fixtures PRIVATE rc_warnings rc_strict_fp)
endif()
