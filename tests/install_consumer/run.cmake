cmake_minimum_required(VERSION 3.25)
# Script mode: installs the build tree into WORK_DIR/prefix, then configures, builds and runs two
# consumer projects against it and checks the pkg-config files:
#   runtime/  an engine: find_package(crepuscular) (runtime only), its own EGL context, the prefilter
#             and evaluation passes on it, then a crep::Scattering frame from its own reversed-Z camera
#             matrices and shadow map; its link line must not mention OpenEXR or stb
#   support/  a tool: find_package(crepuscular COMPONENTS support), an EXR round trip
#   vulkan    the Vulkan engine example (examples/vulkan_engine/, when built with CREP_VULKAN):
#             find_package(crepuscular COMPONENTS vulkan support), its own device, depth pre-pass and shadow
#             map, crepuscular recorded into its 10 frames (3 in flight), validation layer with
#             synchronization validation on and silent, the EXR written
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 77)
    message(FATAL_ERROR "no GL context (exit 77): ${ARGN}\n${out}\n${err}\n"
                        "This test needs OpenGL 4.5 through EGL (Mesa llvmpipe); it is not skipped.")
  elseif(NOT rc EQUAL 0)
    message(FATAL_ERROR "command failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)

# The portable shaders: every pass of resources.json has its SPIR-V, HLSL and MSL in the install tree, and
# every pass of the library (its GLSL, installed too) is in resources.json.
set(shaders ${WORK_DIR}/prefix/share/crepuscular/shaders)
file(READ ${shaders}/resources.json resources)
string(JSON count LENGTH "${resources}" passes)
math(EXPR last "${count} - 1")
set(described)
foreach(i RANGE ${last})
  string(JSON name GET "${resources}" passes ${i} name)
  list(APPEND described ${name})
  foreach(form spirv hlsl msl)
    string(JSON file GET "${resources}" passes ${i} ${form})
    if(NOT EXISTS ${shaders}/${file})
      message(FATAL_ERROR "installed resources.json names ${file} (${name}), which is not installed")
    endif()
  endforeach()
endforeach()
file(GLOB_RECURSE installed_passes RELATIVE ${WORK_DIR}/prefix/share/crepuscular/glsl
     ${WORK_DIR}/prefix/share/crepuscular/glsl/passes/*.comp)
foreach(pass IN LISTS installed_passes)
  if(NOT pass IN_LIST described)
    message(FATAL_ERROR "the installed pass ${pass} has no entry in resources.json")
  endif()
endforeach()
list(LENGTH installed_passes installed_count)
if(NOT installed_count EQUAL count)
  message(FATAL_ERROR "${installed_count} passes installed, ${count} in resources.json")
endif()
# The declared variants (resources.json's "variants"): each with its three files, and every installed
# SPIR-V file is a pass's or a variant's.
string(JSON variant_count LENGTH "${resources}" variants)
set(shipped_spirv)
foreach(i RANGE ${last})
  string(JSON file GET "${resources}" passes ${i} spirv)
  list(APPEND shipped_spirv ${file})
endforeach()
if(variant_count GREATER 0)
  math(EXPR last_variant "${variant_count} - 1")
  foreach(i RANGE ${last_variant})
    string(JSON name GET "${resources}" variants ${i} name)
    foreach(form spirv hlsl msl)
      string(JSON file GET "${resources}" variants ${i} ${form})
      if(NOT EXISTS ${shaders}/${file})
        message(FATAL_ERROR "installed resources.json names ${file} (a variant of ${name}), which is not "
                            "installed")
      endif()
    endforeach()
    string(JSON file GET "${resources}" variants ${i} spirv)
    list(APPEND shipped_spirv ${file})
  endforeach()
endif()
file(GLOB_RECURSE installed_spirv RELATIVE ${shaders} ${shaders}/spirv/*.spv)
foreach(file IN LISTS installed_spirv)
  if(NOT file IN_LIST shipped_spirv)
    message(FATAL_ERROR "the installed ${file} is in neither \"passes\" nor \"variants\" of resources.json")
  endif()
endforeach()
message(STATUS "portable shaders: ${count} passes and ${variant_count} variants with SPIR-V, HLSL and MSL in "
               "${shaders}")

set(consumers runtime support)
if(EXISTS ${WORK_DIR}/prefix/include/crep/vulkan/vulkan_backend.h) # built with CREP_VULKAN
  list(APPEND consumers vulkan)
endif()
foreach(consumer IN LISTS consumers)
  set(build ${WORK_DIR}/${consumer})
  set(source ${CONSUMER_SOURCE}/${consumer})
  set(program consumer)
  set(arguments ${build})
  if(consumer STREQUAL "vulkan") # the Vulkan engine example itself, built against the install tree
    set(source ${SOURCE_DIR}/examples/vulkan_engine)
    set(program crep-vulkan-engine)
    set(arguments --validation --frames 10 --width 160 --height 90 --out ${build})
  endif()
  run(${CMAKE_COMMAND} -S ${source} -B ${build} -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
  run(${CMAKE_COMMAND} --build ${build})
  file(READ ${build}/CMakeFiles/${program}.dir/link.txt link_line)
  string(STRIP "${link_line}" link_line)
  message(STATUS "${consumer} consumer link line: ${link_line}")
  set(link_${consumer} "${link_line}")
  run(${build}/${program} ${arguments})
endforeach()
if(link_vulkan AND NOT EXISTS ${WORK_DIR}/vulkan/vulkan-engine.exr)
  message(FATAL_ERROR "the Vulkan engine example wrote no ${WORK_DIR}/vulkan/vulkan-engine.exr")
endif()
# An engine linking only the runtime library gets neither OpenEXR (nor Imath / Iex) nor stb.
if(link_runtime MATCHES "[Oo]pen[Ee][Xx][Rr]|Imath|Iex|stb")
  message(FATAL_ERROR "the runtime consumer's link line mentions OpenEXR or stb (${CMAKE_MATCH_0}):\n${link_runtime}")
endif()
if(NOT link_runtime MATCHES "libcrepuscular\\.(a|so)" OR link_runtime MATCHES "crepuscular_support")
  message(FATAL_ERROR "the runtime consumer must link libcrepuscular and not the support library:\n${link_runtime}")
endif()
if(NOT link_support MATCHES "libcrepuscular_support\\.(a|so)")
  message(FATAL_ERROR "the support consumer does not link libcrepuscular_support:\n${link_support}")
endif()

# BUILD_SHARED_LIBS: the runtime library built from source as a shared library (without tools, tests and
# benchmarks), installed, and linked by the same engine consumer. Its compile line must carry no include
# directory of the library's private dependencies (Eigen, OpenEXR, Imath): a shared runtime library
# requires none of them of an engine.
set(shared ${WORK_DIR}/shared-build)
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${shared} -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON
    -DCREP_BUILD_TESTS=OFF -DCREP_BUILD_TOOLS=OFF -DCREP_BUILD_BENCH=OFF)
run(${CMAKE_COMMAND} --build ${shared} --parallel 2)
run(${CMAKE_COMMAND} --install ${shared} --prefix ${WORK_DIR}/shared-prefix)
set(build ${WORK_DIR}/runtime-shared)
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE}/runtime -B ${build} -DCMAKE_PREFIX_PATH=${WORK_DIR}/shared-prefix
    -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${build})
file(READ ${build}/CMakeFiles/consumer.dir/link.txt link_shared)
file(READ ${build}/CMakeFiles/consumer.dir/flags.make flags_shared)
message(STATUS "shared runtime consumer link line: ${link_shared}")
if(NOT link_shared MATCHES "libcrepuscular\\.so")
  message(FATAL_ERROR "the shared-library consumer does not link libcrepuscular.so:\n${link_shared}")
endif()
if(flags_shared MATCHES "[Ee]igen|OpenEXR|Imath")
  message(FATAL_ERROR "the shared runtime consumer's compile flags name a private dependency (${CMAKE_MATCH_0}):\n"
                      "${flags_shared}")
endif()
run(${build}/consumer ${build})

# pkg-config: both files resolve; the runtime one names no OpenEXR, even with --static.
find_program(PKG_CONFIG pkg-config REQUIRED)
file(GLOB_RECURSE pc ${WORK_DIR}/prefix/*/crepuscular.pc)
get_filename_component(pcdir "${pc}" DIRECTORY)
set(ENV{PKG_CONFIG_PATH} "${pcdir}")
foreach(args "--libs;--cflags;crepuscular" "--libs;--static;crepuscular" "--libs;--cflags;crepuscular-support")
  execute_process(COMMAND ${PKG_CONFIG} ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE flags ERROR_VARIABLE err)
  string(STRIP "${flags}" flags)
  string(REPLACE ";" " " shown "${args}")
  if(NOT rc EQUAL 0 OR NOT flags MATCHES "-lcrepuscular")
    message(FATAL_ERROR "pkg-config ${shown} failed: ${flags}\n${err}")
  endif()
  message(STATUS "pkg-config ${shown}: ${flags}")
  if(shown MATCHES "crepuscular$" AND flags MATCHES "OpenEXR|Imath|Iex|stb")
    message(FATAL_ERROR "pkg-config ${shown} mentions OpenEXR or stb: ${flags}")
  endif()
  if(shown MATCHES "crepuscular-support$" AND NOT flags MATCHES "-lcrepuscular_support")
    message(FATAL_ERROR "pkg-config ${shown} does not name the support library: ${flags}")
  endif()
endforeach()
