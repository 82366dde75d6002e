# Portable shaders: every pass of the library (glsl/passes/<module>/<name>.comp, its default variant) and the
# variants a frame uses (glsl/portable_variants.txt) are compiled to Vulkan SPIR-V (glslc), validated
# (spirv-val), cross-compiled to HLSL Shader Model 6.0 and to MSL 2.1 (spirv-cross), the HLSL is compiled
# back by glslang's HLSL front end as a check and, with the Vulkan attributes a D3D12 engine's HLSL lacks,
# to the SPIR-V the tests run (hlsl_vulkan/, not installed), and the resources of all of them are described
# in one resources.json (spirv-cross --reflect, merged by CrepShaderManifest.cmake). Output in
# ${CMAKE_BINARY_DIR}/shaders, installed to share/crepuscular/shaders/{spirv,hlsl,msl,resources.json}.
# docs/PORTABLE_SHADERS.md has the rules.
#
# Bindings: one descriptor set (0); a resource's Vulkan binding is its GL binding number (glsl/crep/
# bindings.h) plus the base of its kind, CREP_VULKAN_*_BASE of the same header, read from it here.

option(CREP_PORTABLE_SHADERS "Compile the library's shaders to SPIR-V, HLSL and MSL (glslc, spirv-tools, spirv-cross)" ON)
if(NOT CREP_PORTABLE_SHADERS)
  return()
endif()

foreach(tool_package IN ITEMS "glslc:glslc" "spirv-val:spirv-tools" "spirv-opt:spirv-tools"
                               "spirv-cross:spirv-cross" "glslangValidator:glslang-tools")
  string(REPLACE ":" ";" pair "${tool_package}")
  list(GET pair 0 tool)
  list(GET pair 1 package)
  string(TOUPPER "CREP_${tool}" variable)
  string(REPLACE "-" "_" variable "${variable}")
  find_program(${variable} ${tool})
  if(NOT ${variable})
    message(FATAL_ERROR "CREP_PORTABLE_SHADERS: ${tool} not found; install the Debian package ${package} "
                        "(the README's install step does) or configure with -DCREP_PORTABLE_SHADERS=OFF")
  endif()
endforeach()

set(CREP_SHADER_SOURCE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/glsl)
set(CREP_SHADER_OUTPUT_DIR ${CMAKE_BINARY_DIR}/shaders)

# The binding bases, named once in bindings.h.
file(STRINGS ${CREP_SHADER_SOURCE_DIR}/crep/bindings.h base_lines REGEX "^#define CREP_VULKAN_[A-Z]+_BASE")
foreach(kind IN ITEMS UNIT IMAGE UNIFORM STORAGE)
  set(CREP_VULKAN_${kind}_BASE "")
  foreach(line IN LISTS base_lines)
    if(line MATCHES "^#define CREP_VULKAN_${kind}_BASE +([0-9]+)")
      set(CREP_VULKAN_${kind}_BASE ${CMAKE_MATCH_1})
    endif()
  endforeach()
  if(CREP_VULKAN_${kind}_BASE STREQUAL "")
    message(FATAL_ERROR "glsl/crep/bindings.h: no #define CREP_VULKAN_${kind}_BASE")
  endif()
endforeach()

file(GLOB_RECURSE crep_shader_includes CONFIGURE_DEPENDS ${CREP_SHADER_SOURCE_DIR}/crep/*.glsl
     ${CREP_SHADER_SOURCE_DIR}/crep/*.h)
file(GLOB_RECURSE crep_shader_passes CONFIGURE_DEPENDS RELATIVE ${CREP_SHADER_SOURCE_DIR}/passes
     ${CREP_SHADER_SOURCE_DIR}/passes/*.comp)
list(SORT crep_shader_passes)

# The sampled textures' bindings (unit base up to the image base): spirv-opt merges the Texture and
# SamplerState glslang makes of the HLSL at each into one combined image sampler (CrepHlslForVulkan.cmake).
math(EXPR crep_last_unit_binding "${CREP_VULKAN_IMAGE_BASE} - 1")
set(crep_sampled_bindings)
foreach(binding RANGE ${CREP_VULKAN_UNIT_BASE} ${crep_last_unit_binding})
  list(APPEND crep_sampled_bindings "0:${binding}")
endforeach()
string(REPLACE ";" " " crep_sampled_bindings "${crep_sampled_bindings}")

set(crep_portable_outputs)
set(crep_reflections)
set(crep_pass_names)

# One shipped shader: passes/<pass>.comp with `defines` (a list of NAME=VALUE) as <out> (<module>/<name> for
# a pass's default variant, <module>/<name>.<tag> for a declared variant) in spirv/, hlsl/, msl/ and
# reflect/; the HLSL compiled back by glslang as a check (hlsl_check/), and its Vulkan form (hlsl_vulkan/:
# CrepHlslForVulkan.cmake's copy, glslang, spirv-opt, spirv-val), which tests/vulkan/ runs.
function(crep_portable_shader pass out defines)
  set(source ${CREP_SHADER_SOURCE_DIR}/passes/${pass}.comp)
  set(dir ${CREP_SHADER_OUTPUT_DIR})
  set(spv ${dir}/spirv/${out}.spv)
  set(hlsl ${dir}/hlsl/${out}.hlsl)
  set(msl ${dir}/msl/${out}.metal)
  set(reflection ${dir}/reflect/${out}.json)
  set(hlsl_check ${dir}/hlsl_check/${out}.spv)
  set(vulkan_hlsl ${dir}/hlsl_vulkan/${out}.hlsl)
  set(vulkan_glslang ${dir}/hlsl_vulkan/${out}.glslang.spv)
  set(vulkan_spv ${dir}/hlsl_vulkan/${out}.spv)
  get_filename_component(module_dir ${pass} DIRECTORY)
  set(glslc_defines)
  foreach(define IN LISTS defines)
    list(APPEND glslc_defines "-D${define}")
  endforeach()
  add_custom_command(
    OUTPUT ${spv} ${hlsl} ${msl} ${reflection} ${hlsl_check} ${vulkan_hlsl} ${vulkan_spv}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}/spirv/${module_dir} ${dir}/hlsl/${module_dir}
            ${dir}/msl/${module_dir} ${dir}/reflect/${module_dir} ${dir}/hlsl_check/${module_dir}
            ${dir}/hlsl_vulkan/${module_dir}
    COMMAND ${CREP_GLSLC} --target-env=vulkan1.1 -Werror -I ${CREP_SHADER_SOURCE_DIR}
            -ftexture-binding-base ${CREP_VULKAN_UNIT_BASE} -fsampler-binding-base ${CREP_VULKAN_UNIT_BASE}
            -fimage-binding-base ${CREP_VULKAN_IMAGE_BASE} -fubo-binding-base ${CREP_VULKAN_UNIFORM_BASE}
            -fssbo-binding-base ${CREP_VULKAN_STORAGE_BASE} ${glslc_defines} -o ${spv} ${source}
    COMMAND ${CREP_SPIRV_VAL} --target-env vulkan1.1 ${spv}
    COMMAND ${CREP_SPIRV_CROSS} ${spv} --hlsl --shader-model 60 --output ${hlsl}
    COMMAND ${CREP_GLSLANGVALIDATOR} -D -S comp -e main -V --target-env vulkan1.1 -o ${hlsl_check} ${hlsl}
    COMMAND ${CREP_SPIRV_CROSS} ${spv} --msl --msl-version 20100 --msl-decoration-binding --output ${msl}
    COMMAND ${CREP_SPIRV_CROSS} ${spv} --reflect --output ${reflection}
    COMMAND ${CMAKE_COMMAND} -DHLSL=${hlsl} -DREFLECTION=${reflection} -DOUTPUT=${vulkan_hlsl} -P
            ${PROJECT_SOURCE_DIR}/cmake/CrepHlslForVulkan.cmake
    COMMAND ${CREP_GLSLANGVALIDATOR} -D -S comp -e main -V --target-env vulkan1.1 --no-storage-format --quiet
            -o ${vulkan_glslang} ${vulkan_hlsl}
    COMMAND ${CREP_SPIRV_OPT} --convert-to-sampled-image=${crep_sampled_bindings} -o ${vulkan_spv}
            ${vulkan_glslang}
    COMMAND ${CREP_SPIRV_VAL} --target-env vulkan1.1 ${vulkan_spv}
    DEPENDS ${source} ${crep_shader_includes} ${PROJECT_SOURCE_DIR}/cmake/CrepHlslForVulkan.cmake
    COMMENT "Portable shader ${out}: SPIR-V, HLSL, MSL; the HLSL for Vulkan"
    VERBATIM)
  set(crep_portable_outputs ${crep_portable_outputs} ${spv} ${hlsl} ${msl} ${hlsl_check} ${vulkan_spv}
      PARENT_SCOPE)
  # File by file (not the folders), so that a variant taken off the list is not installed from an old build.
  set(share ${CMAKE_INSTALL_DATADIR}/crepuscular/shaders)
  install(FILES ${spv} DESTINATION ${share}/spirv/${module_dir})
  install(FILES ${hlsl} DESTINATION ${share}/hlsl/${module_dir})
  install(FILES ${msl} DESTINATION ${share}/msl/${module_dir})
  set(crep_reflections ${crep_reflections} ${reflection} PARENT_SCOPE)
endfunction()

foreach(pass IN LISTS crep_shader_passes) # <module>/<name>.comp
  string(REGEX REPLACE "\\.comp$" "" stem "${pass}")
  crep_portable_shader(${stem} ${stem} "")
  list(APPEND crep_pass_names ${stem})
endforeach()

# The variants a frame uses (the list docs/PORTABLE_SHADERS.md, "Variants", describes), beside the defaults.
set(CREP_SHADER_VARIANTS ${CREP_SHADER_SOURCE_DIR}/portable_variants.txt)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${CREP_SHADER_VARIANTS})
include(${CMAKE_CURRENT_LIST_DIR}/CrepShaderVariants.cmake)
crep_read_shader_variants(${CREP_SHADER_VARIANTS} crep_variant)
if(crep_variant_COUNT GREATER 0)
  math(EXPR last "${crep_variant_COUNT} - 1")
  foreach(i RANGE ${last})
    set(stem ${crep_variant_${i}_PASS})
    if(NOT stem IN_LIST crep_pass_names)
      message(FATAL_ERROR "${CREP_SHADER_VARIANTS}: no pass glsl/passes/${stem}.comp")
    endif()
    crep_portable_shader(${stem} ${stem}.${crep_variant_${i}_TAG} "${crep_variant_${i}_DEFINES}")
  endforeach()
endif()

set(CREP_SHADER_RESOURCES ${CREP_SHADER_OUTPUT_DIR}/resources.json)
string(REPLACE ";" "," crep_pass_list "${crep_pass_names}")
add_custom_command(
  OUTPUT ${CREP_SHADER_RESOURCES}
  COMMAND ${CMAKE_COMMAND} -DOUTPUT=${CREP_SHADER_RESOURCES} -DSHADER_DIR=${CREP_SHADER_OUTPUT_DIR}
          -DPASSES=${crep_pass_list} -DUNIT_BASE=${CREP_VULKAN_UNIT_BASE} -DIMAGE_BASE=${CREP_VULKAN_IMAGE_BASE}
          -DUNIFORM_BASE=${CREP_VULKAN_UNIFORM_BASE} -DSTORAGE_BASE=${CREP_VULKAN_STORAGE_BASE}
          -DVERSION=${PROJECT_VERSION} -DVARIANTS=${CREP_SHADER_VARIANTS} -P
          ${CMAKE_CURRENT_SOURCE_DIR}/cmake/CrepShaderManifest.cmake
  DEPENDS ${crep_reflections} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/CrepShaderManifest.cmake
          ${CREP_SHADER_VARIANTS} ${CMAKE_CURRENT_SOURCE_DIR}/cmake/CrepShaderVariants.cmake
  COMMENT "Portable shaders: resources.json"
  VERBATIM)
add_custom_target(crep_portable_shaders ALL DEPENDS ${crep_portable_outputs} ${CREP_SHADER_RESOURCES})

install(FILES ${CREP_SHADER_RESOURCES} DESTINATION ${CMAKE_INSTALL_DATADIR}/crepuscular/shaders)
