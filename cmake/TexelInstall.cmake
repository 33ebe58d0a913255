# Install rules (TEXEL_INSTALL): the static libraries as exported targets
# texel::<name>, the public headers of the components built, the texel CLI,
# and the CMake package, so that
#   cmake --install build --prefix /opt/texel
#   find_package(texel [COMPONENTS player codec ...])   # CMAKE_PREFIX_PATH=/opt/texel
# works. Each component has its own export file (texel-<component>-targets.cmake);
# texelConfig.cmake loads only the requested components and those they need,
# and looks up only their third-party libraries (TexelDependencies.cmake,
# installed next to it).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
include(${CMAKE_CURRENT_LIST_DIR}/TexelDependencies.cmake)  # TEXEL_COMPONENTS
set(TEXEL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/texel CACHE STRING
    "Where texelConfig.cmake is installed, relative to the prefix")

set(TEXEL_INSTALLED_COMPONENTS "")
foreach(component IN LISTS TEXEL_COMPONENTS)
  get_property(targets GLOBAL PROPERTY TEXEL_COMPONENT_TARGETS_${component})
  if(NOT targets)
    continue()
  endif()
  install(TARGETS ${targets} EXPORT texel-${component}-targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT texel-${component}-targets NAMESPACE texel:: FILE texel-${component}-targets.cmake
          DESTINATION ${TEXEL_INSTALL_CMAKEDIR})
  list(APPEND TEXEL_INSTALLED_COMPONENTS ${component})
endforeach()

if(TARGET texel_cli)
  install(TARGETS texel_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/texelConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/texelConfig.cmake INSTALL_DESTINATION ${TEXEL_INSTALL_CMAKEDIR})
# 0.x: every 0.y release is treated as compatible until 1.0 fixes the API.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/texelConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/texelConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/texelConfigVersion.cmake
              ${CMAKE_CURRENT_LIST_DIR}/TexelDependencies.cmake
        DESTINATION ${TEXEL_INSTALL_CMAKEDIR})
