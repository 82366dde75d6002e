# Installs the two libraries with their headers, the public GLSL includes, one exported CMake package
# with a component per library, and a pkg-config file per library:
#   find_package(crepuscular)                      -> crep::crepuscular (component runtime, the default)
#   find_package(crepuscular COMPONENTS support)   -> crep::support too (EXR, PNG, compare, EGL context)
#   pkg-config crepuscular / crepuscular-support
include(CMakePackageConfigHelpers)

foreach(module IN LISTS CREP_MODULES)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${module}/include/crep)
    install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${module}/include/crep DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endforeach()
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/support/include/crep DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/generated/include/crep/core/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/crep/core)
# Public GLSL includes an engine can #include in its own shaders, and the passes' GLSL for an engine that
# runs them with its own host code (the portable SPIR-V, HLSL and MSL: CrepPortableShaders.cmake).
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/glsl/crep ${CMAKE_CURRENT_SOURCE_DIR}/glsl/passes
        DESTINATION ${CMAKE_INSTALL_DATADIR}/crepuscular/glsl)

set(CREP_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/crepuscular)
set(CREP_COMPONENTS runtime support)
set(CREP_VULKAN_INSTALLED OFF)
set(CREP_VULKAN_STATIC OFF)
if(TARGET crepuscular_vulkan)
  list(APPEND CREP_COMPONENTS vulkan)
  set(CREP_VULKAN_INSTALLED ON)
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/vulkan/include/crep DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endif()
foreach(component IN LISTS CREP_COMPONENTS)
  if(component STREQUAL "runtime")
    set(target crepuscular)
  else()
    set(target crepuscular_${component})
  endif()
  install(TARGETS ${target} EXPORT crepuscular-${component}-targets
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT crepuscular-${component}-targets NAMESPACE crep:: DESTINATION ${CREP_CMAKE_DIR})
  # A static archive carries its private dependencies to the consumer: the config must find them.
  get_target_property(type ${target} TYPE)
  string(TOUPPER ${component} upper)
  if(type STREQUAL "STATIC_LIBRARY")
    set(CREP_${upper}_STATIC ON)
  else()
    set(CREP_${upper}_STATIC OFF)
  endif()
endforeach()

configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/crepuscularConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfig.cmake
  INSTALL_DESTINATION ${CREP_CMAKE_DIR}
  PATH_VARS CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfigVersion.cmake
        DESTINATION ${CREP_CMAKE_DIR})

# Relocatable: the prefix is found relative to the .pc file, so `cmake --install --prefix` works.
file(RELATIVE_PATH CREP_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
foreach(pc crepuscular crepuscular-support)
  configure_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/${pc}.pc.in ${CMAKE_CURRENT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
