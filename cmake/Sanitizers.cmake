# Hostile-input builds (docs/limits.md, issue 10).
#   SHADERGEN_SANITIZE=ON  AddressSanitizer + UndefinedBehaviorSanitizer over the whole suite
#                          (GCC or Clang). Any report aborts the process, so a test fails.
#   SHADERGEN_FUZZ=ON      the libFuzzer targets in tests/fuzz (Clang only), everything built
#                          with ASan + UBSan as well.
# -fno-sanitize=vptr: Debian's glslang is built without RTTI, so UBSan's dynamic type checks
# cannot look up its classes. Run the binaries with the options in cmake/sanitizers/ (env.sh).
option(SHADERGEN_SANITIZE "Build everything with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(SHADERGEN_FUZZ "Build the libFuzzer targets (tests/fuzz; needs Clang)" OFF)

# The instrumentation (tests/CMakeLists.txt leaves it off the tests' own code).
set(SHADERGEN_SANITIZER_FLAGS -fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=all)
if(SHADERGEN_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "SHADERGEN_FUZZ needs Clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++-14")
  endif()
  # Every library gets the coverage instrumentation; only the fuzz targets link libFuzzer's main.
  list(APPEND SHADERGEN_SANITIZER_FLAGS -fsanitize=fuzzer-no-link)
endif()
if(SHADERGEN_SANITIZE OR SHADERGEN_FUZZ)
  # -O1 with line tables: readable stacks, and a build that fits the CI budget on two cores.
  # _GLIBCXX_ASSERTIONS: bounds-checked operator[] on the standard containers as well.
  add_compile_options(${SHADERGEN_SANITIZER_FLAGS} -fno-omit-frame-pointer -O1 $<IF:$<CXX_COMPILER_ID:Clang>,-gline-tables-only,-g1>
                      -D_GLIBCXX_ASSERTIONS)
  add_link_options(-fsanitize=address,undefined)
endif()
