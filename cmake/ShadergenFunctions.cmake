# shadergen_add_vertex_shader(): generate a vertex shader at build time and attach it to
# a target. Loaded by find_package(shadergen) (installed package) and by the top-level
# CMakeLists.txt of shadergen itself (add_subdirectory of the source tree). See docs/cmake.md.
#
#   shadergen_add_vertex_shader(<target>
#     RIG <file> FRAGMENT <file> RULES <file>...
#     [OUTPUT_NAME <name>]      # default: the fragment shader's name without extension
#     [OPTIMIZE]                # -O (spirv-opt)
#     [EMBED]                   # also <name>.spv.h (uint32_t <name>_spv[]), #include-able
#     [HLSL]                    # also <name>.hlsl (Direct3D), translated from the SPIR-V (docs/hlsl-msl.md)
#     [HLSL_SHADER_MODEL <sm>]  # 5.0 (default), 5.1, 6.0 .. 6.7 (needs HLSL)
#     [MSL]                     # also <name>.metal (Metal)
#     [MSL_VERSION <v>]         # 2.0 (default), 1.2, 2.1 .. 2.4, 3.0 (needs MSL)
#     [MSL_PLATFORM <p>]        # macos (default), ios (needs MSL)
#     [TARGET_ENV <env>]        # vulkan1.0 (default) .. vulkan1.3
#     [CAPTURE]                 # transform-feedback build (to read outputs back with sg::rt::Harness)
#     [MAP <Name=sem[,sem...]>...]  # --map overrides of fragment inputs
#     [TEMPLATES <dir>]         # --templates (default: the ones shipped with shadergen)
#     [DEVICE_PROFILE <file>...] # --device-profile: the plan cheapest on that device; several: the
#                               # portable plan, least worst-case regret (docs/device-profiles.md)
#     [MESH head|limb|dawn]     # --mesh: the procedural mesh a YAML rig's profile prices (needs DEVICE_PROFILE)
#     [BAN <rule>...]           # --ban: pin a plan (the fastest one `shadergen bench` names)
#     [PIN <file>]              # --pin: the plan a device timed fastest (bench --pin-out); no device needed
#     [SET <NAME=VALUE>...]     # --set: a rig deformer parameter (level of detail)
#     [DEPENDS <file>...])      # extra dependencies of the generator run
#
# Runs `shadergen generate` in a custom command whose DEPFILE lists every file the
# generator read (rig, fragment shader, every rules file including included ones, the
# template), so editing any of them regenerates this shader and nothing else.
#
# Outputs go to ${CMAKE_CURRENT_BINARY_DIR}/shadergen/<target>/<name>.{vert,spv,json}
# (+ .spv.h with EMBED, .hlsl with HLSL, .metal with MSL; their bindings are in the .json)
# and are added to the target's sources. The target gets:
#   - compile definitions SHADERGEN_<NAME>_SPV="<abs path of .spv>" and
#     SHADERGEN_<NAME>_REFLECTION="<abs path of .json>" (NAME: OUTPUT_NAME upper-cased,
#     non-alphanumerics replaced by '_'), and SHADERGEN_<NAME>_HLSL / _MSL with HLSL / MSL,
#   - with EMBED, that directory as a PRIVATE include directory, so `#include "<name>.spv.h"`
#     works.
# The same paths are set in the caller's scope as SHADERGEN_<NAME>_{GLSL,SPV,REFLECTION,HEADER,HLSL,MSL}.

if(CMAKE_VERSION VERSION_LESS 3.20)
  message(FATAL_ERROR "shadergen_add_vertex_shader() needs CMake 3.20 or newer (DEPFILE support for all generators)")
endif()

# Functions record the policy settings in effect where they are defined. CMP0116 NEW makes
# the Ninja generator rewrite depfile paths the way Ninja expects, whatever the policy
# version of the project that calls the function.
cmake_policy(PUSH)
cmake_policy(VERSION 3.20)

# The generator: the imported shadergen::shadergen of an installed package, or the in-tree
# target when shadergen's source tree was added with add_subdirectory(). Sets OUT_VAR.
function(_shadergen_executable caller out_var)
  if(NOT TARGET shadergen::shadergen)
    message(FATAL_ERROR "${caller}: no shadergen::shadergen target (use find_package(shadergen) or add_subdirectory(<shadergen source>))")
  endif()
  get_target_property(_exe shadergen::shadergen ALIASED_TARGET)
  if(NOT _exe)
    set(_exe shadergen::shadergen)
  endif()
  set(${out_var} ${_exe} PARENT_SCOPE)
endfunction()

function(shadergen_add_vertex_shader target)
  set(options OPTIMIZE EMBED CAPTURE HLSL MSL)
  set(one RIG FRAGMENT OUTPUT_NAME TARGET_ENV TEMPLATES MESH HLSL_SHADER_MODEL MSL_VERSION MSL_PLATFORM PIN)
  set(multi RULES MAP DEPENDS DEVICE_PROFILE BAN SET)
  cmake_parse_arguments(PARSE_ARGV 1 SG "${options}" "${one}" "${multi}")

  if(SG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): unknown arguments: ${SG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT TARGET ${target})
    message(FATAL_ERROR "shadergen_add_vertex_shader: '${target}' is not a target")
  endif()
  foreach(req RIG FRAGMENT RULES)
    if(NOT SG_${req})
      message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): ${req} is required")
    endif()
  endforeach()
  if(SG_TARGET_ENV AND NOT SG_TARGET_ENV MATCHES "^vulkan(1\\.[0-3])?$")
    message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): TARGET_ENV must be vulkan1.0, vulkan1.1, vulkan1.2 or vulkan1.3, not '${SG_TARGET_ENV}'")
  endif()

  if(SG_HLSL_SHADER_MODEL AND NOT SG_HLSL)
    message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): HLSL_SHADER_MODEL needs HLSL")
  endif()
  foreach(o MSL_VERSION MSL_PLATFORM)
    if(SG_${o} AND NOT SG_MSL)
      message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): ${o} needs MSL")
    endif()
  endforeach()
  # The generator refuses these too, but only at build time, once per edit.
  if(SG_MESH AND NOT SG_DEVICE_PROFILE)
    message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): MESH needs DEVICE_PROFILE (without a profile the mesh prices nothing)")
  endif()
  if(SG_MESH AND NOT SG_MESH MATCHES "^(head|limb|dawn)$")
    message(FATAL_ERROR "shadergen_add_vertex_shader(${target}): MESH must be head, limb or dawn, not '${SG_MESH}'")
  endif()

  _shadergen_executable(shadergen_add_vertex_shader _sg_exe)

  # Absolute input paths: the depfile then names the same files the DEPENDS do.
  # A glTF rig may select a primitive, "MODEL.glb#M/P" (docs/gltf.md): the build depends on
  # the model file, and the generator gets the selection as written.
  set(_rig_sel "")
  set(_rig_path "${SG_RIG}")
  if(SG_RIG MATCHES "^(.*\\.([gG][lL][tT][fF]|[gG][lL][bB]))(#[^#]*)$")
    set(_rig_path "${CMAKE_MATCH_1}")
    set(_rig_sel "${CMAKE_MATCH_3}")
  endif()
  get_filename_component(_rig_file "${_rig_path}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(_rig "${_rig_file}${_rig_sel}")
  get_filename_component(_frag "${SG_FRAGMENT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(_rules "")
  set(_rule_args "")
  foreach(r IN LISTS SG_RULES)
    get_filename_component(_r "${r}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _rules "${_r}")
    list(APPEND _rule_args -r "${_r}")
  endforeach()
  set(_extra "")
  foreach(d IN LISTS SG_DEPENDS)
    get_filename_component(_d "${d}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _extra "${_d}")
  endforeach()

  set(_name "${SG_OUTPUT_NAME}")
  if(NOT _name)
    get_filename_component(_name "${_frag}" NAME_WE)
  endif()
  string(MAKE_C_IDENTIFIER "${_name}" _ident)
  string(TOUPPER "${_ident}" _NAME)

  set(_dir "${CMAKE_CURRENT_BINARY_DIR}/shadergen/${target}")
  set(_stem "${_dir}/${_name}")
  set(_depfile "${_stem}.d")
  # Same order as the generator writes them (its depfile names the first one first).
  set(_outputs "${_stem}.vert" "${_stem}.spv")
  set(_emit glsl,spv)
  if(SG_EMBED)
    list(APPEND _outputs "${_stem}.spv.h")
    string(APPEND _emit ",header")
  endif()
  set(_translate "")
  if(SG_HLSL)
    list(APPEND _outputs "${_stem}.hlsl")
    string(APPEND _emit ",hlsl")
    if(SG_HLSL_SHADER_MODEL)
      list(APPEND _translate "--hlsl-shader-model=${SG_HLSL_SHADER_MODEL}")
    endif()
  endif()
  if(SG_MSL)
    list(APPEND _outputs "${_stem}.metal")
    string(APPEND _emit ",msl")
    if(SG_MSL_VERSION)
      list(APPEND _translate "--msl-version=${SG_MSL_VERSION}")
    endif()
    if(SG_MSL_PLATFORM)
      list(APPEND _translate "--msl-platform=${SG_MSL_PLATFORM}")
    endif()
  endif()
  list(APPEND _outputs "${_stem}.json")
  string(APPEND _emit ",reflection")

  set(_args generate --rig "${_rig}" -f "${_frag}" ${_rule_args} -o "${_stem}" --emit ${_emit} ${_translate}
      -MF "${_depfile}" -q)
  if(SG_OPTIMIZE)
    list(APPEND _args -O)
  endif()
  if(SG_TARGET_ENV)
    list(APPEND _args "--target-env=${SG_TARGET_ENV}")
  endif()
  if(SG_CAPTURE)
    list(APPEND _args --capture)
  endif()
  foreach(m IN LISTS SG_MAP)
    list(APPEND _args --map "${m}")
  endforeach()
  if(SG_TEMPLATES)
    get_filename_component(_tpl "${SG_TEMPLATES}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _args --templates "${_tpl}")
  endif()

  foreach(p IN LISTS SG_DEVICE_PROFILE)
    # A dependency as well (the depfile names it too once the generator has run).
    get_filename_component(_profile "${p}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _args --device-profile "${_profile}")
    list(APPEND _extra "${_profile}")
  endforeach()
  if(SG_MESH)
    list(APPEND _args --mesh "${SG_MESH}")
  endif()
  foreach(b IN LISTS SG_BAN)
    list(APPEND _args --ban "${b}")
  endforeach()
  if(SG_PIN)
    get_filename_component(_pin "${SG_PIN}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _args --pin "${_pin}")
    list(APPEND _extra "${_pin}")
  endif()
  foreach(v IN LISTS SG_SET)
    list(APPEND _args --set "${v}")
  endforeach()

  add_custom_command(
    OUTPUT ${_outputs}
    COMMAND ${_sg_exe} ${_args}
    DEPENDS "${_rig_file}" "${_frag}" ${_rules} ${_extra} ${_sg_exe}
    DEPFILE "${_depfile}"
    WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}"
    COMMENT "shadergen: generating vertex shader ${_name} for ${target}"
    VERBATIM)

  target_sources(${target} PRIVATE ${_outputs})
  set_source_files_properties(${_outputs} PROPERTIES GENERATED TRUE)
  # Sources to hand to the engine, not to this build: the Visual Studio generator would run
  # FXC on .hlsl and Xcode the Metal compiler on .metal with their default settings.
  foreach(_translated IN ITEMS "${_stem}.hlsl" "${_stem}.metal")
    if(_translated IN_LIST _outputs)
      set_source_files_properties("${_translated}" PROPERTIES HEADER_FILE_ONLY TRUE)
    endif()
  endforeach()
  target_compile_definitions(${target} PRIVATE
    "SHADERGEN_${_NAME}_SPV=\"${_stem}.spv\""
    "SHADERGEN_${_NAME}_REFLECTION=\"${_stem}.json\"")
  if(SG_EMBED)
    target_include_directories(${target} PRIVATE "${_dir}")
    set(SHADERGEN_${_NAME}_HEADER "${_stem}.spv.h" PARENT_SCOPE)
  endif()
  set(SHADERGEN_${_NAME}_GLSL "${_stem}.vert" PARENT_SCOPE)
  set(SHADERGEN_${_NAME}_SPV "${_stem}.spv" PARENT_SCOPE)
  set(SHADERGEN_${_NAME}_REFLECTION "${_stem}.json" PARENT_SCOPE)
  if(SG_HLSL)
    target_compile_definitions(${target} PRIVATE "SHADERGEN_${_NAME}_HLSL=\"${_stem}.hlsl\"")
    set(SHADERGEN_${_NAME}_HLSL "${_stem}.hlsl" PARENT_SCOPE)
  endif()
  if(SG_MSL)
    target_compile_definitions(${target} PRIVATE "SHADERGEN_${_NAME}_MSL=\"${_stem}.metal\"")
    set(SHADERGEN_${_NAME}_MSL "${_stem}.metal" PARENT_SCOPE)
  endif()
endfunction()

# shadergen_add_shader_variants(): every variant of a manifest (docs/variants.md) built at
# build time, one build edge per variant, and attached to a target.
#
#   shadergen_add_shader_variants(<target>
#     MANIFEST <file>            # the variant manifest (YAML)
#     [OUTPUT_DIR <dir>]         # default: ${CMAKE_CURRENT_BINARY_DIR}/shadergen/<target>/<manifest name>
#     [RULES <file>...]          # rules files read before the manifest's (e.g. ${SHADERGEN_RULES_DIR}/standard.yaml)
#     [DEVICE_PROFILE <file>...] # --device-profile for every variant, in place of the manifest's;
#                                # several: the portable plan across them
#     [VALIDATE]                 # --validate: every variant validated after it is built
#     [CACHE_URL <url>]          # --cache-url: a shared cache over the local one
#     [ONE_COMMAND]              # one `shadergen build` for the whole manifest instead (below)
#     [JOBS <n>]                 # worker threads of that command (default: every hardware thread)
#     [DEPENDS <file>...])       # extra dependencies
#
# The manifest is expanded at configure time (`shadergen build MANIFEST --list-cmake`) and
# again whenever it (or a whole model it expands, MODEL.glb#*) changes. Each variant is its
# own custom command (`shadergen build MANIFEST --variant NAME`) whose DEPFILE lists the
# manifest and every file that variant reads, so Ninja reruns exactly the variants whose
# inputs changed and a distributing build can spread them; one last command
# (`--join`) writes <dir>/index.json (every variant with its plan cost and output files,
# relative to <dir>) from the variants' entries. The outputs are those of one
# `shadergen build` run, byte for byte. The content cache (<dir>/.shadergen-cache) is
# shared by the variants' commands.
#
# Expanding the manifest needs the generator at configure time: an installed package's
# imported shadergen::shadergen. When shadergen is built by the same project
# (add_subdirectory), or with ONE_COMMAND, the manifest is built by one command instead
# (`shadergen build`, all cores: JOBS), whose DEPFILE lists every file any variant read:
# cheaper on one machine (process start-up is paid once), but one unit of scheduling.
#
# The target gets the compile definition SHADERGEN_<NAME>_INDEX="<dir>/index.json" (NAME:
# the manifest's file name up to the first '.', upper-cased, non-alphanumerics as '_'),
# also set in the caller's scope.
function(shadergen_add_shader_variants target)
  cmake_parse_arguments(PARSE_ARGV 1 SG "VALIDATE;ONE_COMMAND" "MANIFEST;OUTPUT_DIR;JOBS;CACHE_URL" "RULES;DEPENDS;DEVICE_PROFILE")
  if(SG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "shadergen_add_shader_variants(${target}): unknown arguments: ${SG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT TARGET ${target})
    message(FATAL_ERROR "shadergen_add_shader_variants: '${target}' is not a target")
  endif()
  if(NOT SG_MANIFEST)
    message(FATAL_ERROR "shadergen_add_shader_variants(${target}): MANIFEST is required")
  endif()
  _shadergen_executable(shadergen_add_shader_variants _sg_exe)
  get_filename_component(_manifest "${SG_MANIFEST}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(_name "${_manifest}" NAME)
  string(REGEX REPLACE "\\..*$" "" _name "${_name}")
  string(MAKE_C_IDENTIFIER "${_name}" _ident)
  string(TOUPPER "${_ident}" _NAME)
  set(_dir "${SG_OUTPUT_DIR}")
  if(NOT _dir)
    set(_dir "${CMAKE_CURRENT_BINARY_DIR}/shadergen/${target}/${_name}")
  endif()
  get_filename_component(_dir "${_dir}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  set(_extra "")
  foreach(d IN LISTS SG_DEPENDS)
    get_filename_component(_d "${d}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _extra "${_d}")
  endforeach()
  # What every command is given; --list-cmake only what decides the variants' files.
  set(_list_args -o "${_dir}")
  foreach(r IN LISTS SG_RULES)
    get_filename_component(_r "${r}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _list_args -r "${_r}")
  endforeach()
  foreach(p IN LISTS SG_DEVICE_PROFILE)
    get_filename_component(_profile "${p}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND _list_args --device-profile "${_profile}")
    list(APPEND _extra "${_profile}")
  endforeach()
  set(_args ${_list_args} -q)
  if(SG_VALIDATE)
    list(APPEND _args --validate)
  endif()
  if(SG_CACHE_URL)
    list(APPEND _args --cache-url "${SG_CACHE_URL}")
  endif()
  set(_index "${_dir}/index.json")

  get_target_property(_imported ${_sg_exe} IMPORTED)
  if(_imported)
    get_target_property(_sg_path ${_sg_exe} LOCATION)
  endif()
  if(SG_ONE_COMMAND OR NOT _imported OR NOT EXISTS "${_sg_path}")
    message(VERBOSE "shadergen_add_shader_variants(${target}): ${_name} is built by one command (ONE_COMMAND, or a generator built by this project)")
    if(SG_JOBS)
      list(APPEND _args -j "${SG_JOBS}")
    endif()
    add_custom_command(
      OUTPUT "${_index}"
      COMMAND ${_sg_exe} build "${_manifest}" ${_args}
      DEPENDS "${_manifest}" ${_extra} ${_sg_exe}
      DEPFILE "${_index}.d"
      WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}"
      COMMENT "shadergen: building the shader variants of ${_name} for ${target}"
      VERBATIM)
  else()
    # The manifest's expansion, read back as SHADERGEN_LIST_* variables (function scope).
    set(_list "${CMAKE_CURRENT_BINARY_DIR}/shadergen/${target}/${_name}.variants.cmake")
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${_manifest}")  # also when it fails
    file(MAKE_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}/shadergen/${target}")
    execute_process(
      COMMAND "${_sg_path}" build "${_manifest}" ${_list_args} --list-cmake
      WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}"
      OUTPUT_FILE "${_list}"
      ERROR_VARIABLE _err
      RESULT_VARIABLE _rc)
    if(NOT _rc EQUAL 0)
      message(FATAL_ERROR "shadergen_add_shader_variants(${target}): cannot expand the manifest:\n${_err}")
    endif()
    include("${_list}")
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${SHADERGEN_LIST_CONFIGURE_DEPENDS})
    # A variant depends on the manifest through its stamp, rewritten only when the manifest
    # changes what that variant makes: adding a variant to the manifest reruns only it.
    set(_stamps "${CMAKE_CURRENT_BINARY_DIR}/shadergen/${target}/${_name}.stamps")
    set(_entries "")
    foreach(_v IN LISTS SHADERGEN_LIST_VARIANTS)
      file(CONFIGURE OUTPUT "${_stamps}/${_v}" CONTENT "${SHADERGEN_LIST_${_v}_STAMP}\n")
      add_custom_command(
        OUTPUT ${SHADERGEN_LIST_${_v}_ENTRY} ${SHADERGEN_LIST_${_v}_OUTPUTS}
        COMMAND ${_sg_exe} build "${_manifest}" ${_args} --variant ${_v}
        DEPENDS "${_stamps}/${_v}" ${SHADERGEN_LIST_${_v}_INPUTS} ${_extra} ${_sg_exe}
        DEPFILE ${SHADERGEN_LIST_${_v}_DEPFILE}
        WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}"
        COMMENT "shadergen: building shader variant ${_v} of ${_name}"
        VERBATIM)
      list(APPEND _entries ${SHADERGEN_LIST_${_v}_ENTRY})
    endforeach()
    list(LENGTH SHADERGEN_LIST_VARIANTS _count)
    add_custom_command(
      OUTPUT "${_index}" "${_index}.d"
      COMMAND ${_sg_exe} build "${_manifest}" ${_args} --join
      DEPENDS "${_manifest}" ${_entries} ${_sg_exe}
      WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}"
      COMMENT "shadergen: indexing the ${_count} shader variants of ${_name} for ${target}"
      VERBATIM)
    # SPIR-V files are named by their content (unknown here): cleaned as a folder.
    set_property(TARGET ${target} APPEND PROPERTY ADDITIONAL_CLEAN_FILES "${_dir}/spirv")
  endif()
  target_sources(${target} PRIVATE "${_index}")
  set_source_files_properties("${_index}" PROPERTIES GENERATED TRUE)
  target_compile_definitions(${target} PRIVATE "SHADERGEN_${_NAME}_INDEX=\"${_index}\"")
  set(SHADERGEN_${_NAME}_INDEX "${_index}" PARENT_SCOPE)
endfunction()

cmake_policy(POP)
