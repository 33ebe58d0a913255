# Install rules (TEXEL_INSTALL): the libraries as exported targets
# texel::<name> (static, but for the C library's libtexel.so), the public headers of the components built
# (but those of TEXEL_UNINSTALLED_COMPONENTS: the studio's, cmake/TexelComponents.cmake), the texel CLI,
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
  if(NOT targets OR component IN_LIST TEXEL_UNINSTALLED_COMPONENTS)
    continue()
  endif()
  # One install component per Texel component (cmake --install build --component capi),
  # for packagers and for tests that need only part of an installation.
  install(TARGETS ${targets} EXPORT texel-${component}-targets COMPONENT ${component}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT texel-${component}-targets NAMESPACE texel:: FILE texel-${component}-targets.cmake
          DESTINATION ${TEXEL_INSTALL_CMAKEDIR} COMPONENT ${component})
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

# pkg-config for C programs: texel.pc describes libtexel (the C ABI).
#   cc app.c $(pkg-config --cflags --libs texel)            # libtexel.so
#   pkg-config --static --libs texel                        # + what libtexel.a needs
# Relocatable: the prefix is found from the .pc file's own place.
if(TARGET texel_c)
  file(RELATIVE_PATH _texel_pc_to_prefix ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
  string(REGEX REPLACE "/$" "" _texel_pc_to_prefix "${_texel_pc_to_prefix}")
  get_property(_texel_c_static_libs GLOBAL PROPERTY TEXEL_C_STATIC_LIBS)
  list(TRANSFORM _texel_c_static_libs PREPEND -l OUTPUT_VARIABLE _texel_pc_private)
  list(JOIN _texel_pc_private " " TEXEL_PC_LIBS_PRIVATE)
  set(TEXEL_PC_PREFIX "\${pcfiledir}/${_texel_pc_to_prefix}")
  configure_file(${CMAKE_CURRENT_LIST_DIR}/texel.pc.in ${CMAKE_CURRENT_BINARY_DIR}/texel.pc @ONLY)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/texel.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT capi)
endif()
