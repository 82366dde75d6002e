# The Vulkan side of what a D3D12 engine does with the installed HLSL, so that the build can compile that
# HLSL with glslang's HLSL front end and run it on Vulkan (tests/vulkan/InstalledHlslVulkanTest.cpp). Writes
# a copy of one pass's HLSL with two kinds of Vulkan attributes added; the installed HLSL is not changed.
#   cmake -DHLSL=<pass>.hlsl -DREFLECTION=<pass>.json -DOUTPUT=<copy>.hlsl -P CrepHlslForVulkan.cmake
#
# - The push-constant block: spirv-cross writes it as a cbuffer without a register, which D3D12 binds as root
#   constants at b0. glslang would make it a uniform buffer at binding 0 (a sampled texture's); the copy
#   marks it [[vk::push_constant]].
# - Storage image formats: HLSL has none (a D3D12 UAV's format comes with its view), and glslang infers one
#   from the element type (float4: rgba32f), wrong for an rgba8 or rgba16f image. The copy gives each storage
#   image the format the GLSL declares ([[spv::format_<format>]], from spirv-cross's reflection of the
#   GLSL's SPIR-V); glslang runs with --no-storage-format, so an image the GLSL leaves without one stays so.
# Sampled textures (a Texture + SamplerState pair at t<n> / s<n>, i.e. binding n twice) are merged into one
# combined image sampler after glslang, by spirv-opt --convert-to-sampled-image (CrepPortableShaders.cmake).
# docs/PORTABLE_SHADERS.md, "The HLSL, run".
cmake_minimum_required(VERSION 3.25)

file(READ ${HLSL} text)
file(READ ${REFLECTION} reflection)

string(JSON push ERROR_VARIABLE no_push GET "${reflection}" push_constants 0 type)
if(NOT no_push)
  string(JSON block GET "${reflection}" types ${push} name)
  string(REGEX MATCH "\ncbuffer ${block}\n" found "\n${text}")
  if(NOT found)
    message(FATAL_ERROR "${HLSL}: no \"cbuffer ${block}\" without a register (the push-constant block)")
  endif()
  string(REGEX REPLACE "(^|\n)cbuffer ${block}\n" "\\1[[vk::push_constant]] cbuffer ${block}\n" text
                       "${text}")
endif()

string(JSON count ERROR_VARIABLE no_images LENGTH "${reflection}" images)
if(NOT no_images AND count GREATER 0)
  math(EXPR last "${count} - 1")
  foreach(i RANGE ${last})
    string(JSON name GET "${reflection}" images ${i} name)
    string(JSON format ERROR_VARIABLE no_format GET "${reflection}" images ${i} format)
    if(no_format)
      continue() # written without a format: Unknown (--no-storage-format)
    endif()
    set(declaration "(^|\n)(RW[A-Za-z0-9]+<[^>\n]+> ${name} : register\\()")
    string(REGEX MATCH "${declaration}" found "${text}")
    if(NOT found)
      message(FATAL_ERROR "${HLSL}: no declaration of the storage image \"${name}\"")
    endif()
    string(REGEX REPLACE "${declaration}" "\\1[[spv::format_${format}]] \\2" text "${text}")
  endforeach()
endif()

file(WRITE ${OUTPUT} "${text}")
