// The source of the precompiled-header targets (tests/CMakeLists.txt): a library needs one.
