# Install rules: the library, its header, a CMake package (tclod::tclod) and a
# pkg-config file. Included at the end of the top-level CMakeLists.txt, after
# GNUInstallDirs.

option(TCLOD_INSTALL "Generate the install rules" ${PROJECT_IS_TOP_LEVEL})
if(NOT TCLOD_INSTALL)
  return()
endif()

include(CMakePackageConfigHelpers)

set(TCLOD_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/tclod"
    CACHE STRING "Where tclodConfig.cmake is installed, relative to the prefix")
mark_as_advanced(TCLOD_INSTALL_CMAKEDIR)

install(TARGETS tclod
  EXPORT tclodTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/tclod
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")

install(EXPORT tclodTargets
  NAMESPACE tclod::
  DESTINATION ${TCLOD_INSTALL_CMAKEDIR})

configure_package_config_file(
  ${CMAKE_CURRENT_LIST_DIR}/tclodConfig.cmake.in
  ${PROJECT_BINARY_DIR}/tclodConfig.cmake
  INSTALL_DESTINATION ${TCLOD_INSTALL_CMAKEDIR})
write_basic_package_version_file(
  ${PROJECT_BINARY_DIR}/tclodConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMajorVersion)
install(FILES
  ${PROJECT_BINARY_DIR}/tclodConfig.cmake
  ${PROJECT_BINARY_DIR}/tclodConfigVersion.cmake
  DESTINATION ${TCLOD_INSTALL_CMAKEDIR})

# pkg-config. The file is written at install time so that its prefix is the
# one actually installed to (cmake --install --prefix overrides the configured
# CMAKE_INSTALL_PREFIX).
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(_tclod_pc_libdir "${CMAKE_INSTALL_LIBDIR}")
else()
  set(_tclod_pc_libdir "\${exec_prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(_tclod_pc_includedir "${CMAKE_INSTALL_INCLUDEDIR}")
else()
  set(_tclod_pc_includedir "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
if(BUILD_SHARED_LIBS)
  set(_tclod_pc_cflags "")
else()
  set(_tclod_pc_cflags " -DTCLOD_STATIC")
endif()

install(CODE "
set(TCLOD_PC_PREFIX \"\${CMAKE_INSTALL_PREFIX}\")
set(TCLOD_PC_LIBDIR [==[${_tclod_pc_libdir}]==])
set(TCLOD_PC_INCLUDEDIR [==[${_tclod_pc_includedir}]==])
set(TCLOD_PC_VERSION [==[${PROJECT_VERSION}]==])
set(TCLOD_PC_DESCRIPTION [==[${PROJECT_DESCRIPTION}]==])
set(TCLOD_PC_CFLAGS [==[${_tclod_pc_cflags}]==])
configure_file([==[${CMAKE_CURRENT_LIST_DIR}/tclod.pc.in]==]
               [==[${PROJECT_BINARY_DIR}/tclod.pc]==] @ONLY)
")
install(FILES ${PROJECT_BINARY_DIR}/tclod.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

unset(_tclod_pc_libdir)
unset(_tclod_pc_includedir)
unset(_tclod_pc_cflags)
