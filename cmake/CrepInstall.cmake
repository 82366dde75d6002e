# Installs headers, the library, the public GLSL includes, an exported CMake package and a
# pkg-config file. A consumer does find_package(crepuscular) and links crep::crepuscular.
include(CMakePackageConfigHelpers)

foreach(module IN LISTS CREP_MODULES)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${module}/include/crep)
    install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${module}/include/crep DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endforeach()
# Public GLSL includes an engine can #include in its own shaders.
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/glsl/crep DESTINATION ${CMAKE_INSTALL_DATADIR}/crepuscular/glsl)

install(TARGETS crepuscular EXPORT crepuscularTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT crepuscularTargets NAMESPACE crep:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/crepuscular)

get_target_property(crep_library_type crepuscular TYPE)
if(crep_library_type STREQUAL "STATIC_LIBRARY")
  set(CREP_CONFIG_STATIC ON)
else()
  set(CREP_CONFIG_STATIC OFF)
endif()
configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/crepuscularConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/crepuscular
  PATH_VARS CMAKE_INSTALL_DATADIR)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/crepuscularConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/crepuscular)

# Relocatable: the prefix is found relative to the .pc file, so `cmake --install --prefix` works.
file(RELATIVE_PATH CREP_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/crepuscular.pc.in ${CMAKE_CURRENT_BINARY_DIR}/crepuscular.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/crepuscular.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
