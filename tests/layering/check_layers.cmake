# The generator's stages are layered one way: a file in one stage folder may include
# headers of its own stage and of the stages before it, never of a later one.
# Usage: cmake -DGENERATOR_DIR=<src>/generator -P check_layers.cmake
# (docs/design.md, "Layering", names the order and why.)
set(layers
  common     # diagnostics, types, YAML helpers, the glslang/SPIRV-Tools wrapper
  rig        # rig loaders (YAML, glTF)
  rules      # rules loader, expressions, snippet templates, rule instantiation
  interface  # fragment shader reflection, varyings
  search     # the problem, A*, heuristics, plans
  emit       # GLSL emission, SPIR-V compile, reflection JSON
  analysis   # probes, auto costs, explain, graph, check
  pipeline   # the named stages and generate()
  variants   # manifests, the content cache, batch builds
  api        # the public shadergen::core facade
  validate   # lavapipe runs against the GLM reference
  render     # images of generated shaders (runtime/vk_render)
  measure    # device measurement: GPU timing (bench), calibration of device profiles
  bake       # offline rig data (occlusion with Embree); poses glTF models as validation does
  cli)       # the command line
set(external runtime)  # separate library (no generator dependency), usable from validate up
if(NOT GENERATOR_DIR)
  message(FATAL_ERROR "pass -DGENERATOR_DIR=...")
endif()
file(GLOB_RECURSE sources RELATIVE "${GENERATOR_DIR}" "${GENERATOR_DIR}/*.h" "${GENERATOR_DIR}/*.cpp")
set(violations "")
foreach(src IN LISTS sources)
  string(REGEX MATCH "^[^/]+" stage "${src}")
  if(stage STREQUAL src)  # a file at the top of generator/
    continue()
  endif()
  list(FIND layers "${stage}" rank)
  if(rank EQUAL -1)
    string(APPEND violations "  ${src}: folder '${stage}' is not in the layer list of check_layers.cmake\n")
    continue()
  endif()
  file(STRINGS "${GENERATOR_DIR}/${src}" includes REGEX "^[ \t]*#[ \t]*include[ \t]*\"[^\"]+\"")
  foreach(line IN LISTS includes)
    string(REGEX REPLACE "^[^\"]*\"([^\"]+)\".*$" "\\1" header "${line}")
    string(REGEX MATCH "^[^/]+" target "${header}")
    if(target STREQUAL header)  # same-folder include without a path
      continue()
    endif()
    list(FIND external "${target}" ext)
    if(NOT ext EQUAL -1)
      list(FIND layers validate vrank)
      if(rank LESS vrank)
        string(APPEND violations "  ${src}: includes \"${header}\" (the runtime is only for validate and above)\n")
      endif()
      continue()
    endif()
    list(FIND layers "${target}" trank)
    if(trank EQUAL -1)
      string(APPEND violations "  ${src}: includes \"${header}\" from unknown folder '${target}'\n")
    elseif(trank GREATER rank)
      string(APPEND violations "  ${src}: stage '${stage}' includes \"${header}\" of the later stage '${target}'\n")
    endif()
  endforeach()
endforeach()
if(violations)
  message(FATAL_ERROR "layering violations (a stage includes only itself and earlier stages):\n${violations}")
endif()
list(LENGTH sources n)
message(STATUS "layering holds for ${n} files")
