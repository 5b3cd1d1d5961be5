// The precompiled header of the test executables (tests/CMakeLists.txt, SG_TEST_PCH) is
// built with this empty file.
