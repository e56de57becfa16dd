# Install rules: the library, its header, a CMake package (tclod::tclod), a
# pkg-config file and the license. Included at the end of the top-level
# CMakeLists.txt.

option(TCLOD_INSTALL "Generate the install rules" ${PROJECT_IS_TOP_LEVEL})
if(NOT TCLOD_INSTALL)
  return()
endif()

# Only here: its CMAKE_INSTALL_* cache entries are not a subdirectory's to add
# unless it installs.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(TCLOD_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/tclod"
    CACHE STRING "Where tclodConfig.cmake is installed, relative to the prefix")
mark_as_advanced(TCLOD_INSTALL_CMAKEDIR)

install(TARGETS tclod
  EXPORT tclodTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/tclod
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")

install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

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
# libm, per library kind. A static library cannot bring its own dependencies:
# -lm goes in Libs, since `pkg-config --libs` without --static and CMake's
# pkg_check_modules(... IMPORTED_TARGET) read Libs only. A shared library
# records libm itself (DT_NEEDED), so -lm goes in Libs.private, for those who
# link everything statically. TCLOD_STATIC is public for a static library, as
# in the CMake package.
set(_tclod_pc_libm "")
if(UNIX)
  set(_tclod_pc_libm " -lm")
endif()
if(BUILD_SHARED_LIBS)
  set(_tclod_pc_cflags "")
  set(_tclod_pc_libs "")
  set(_tclod_pc_libs_private "${_tclod_pc_libm}")
else()
  set(_tclod_pc_cflags " -DTCLOD_STATIC")
  set(_tclod_pc_libs "${_tclod_pc_libm}")
  set(_tclod_pc_libs_private "")
endif()

install(CODE "
set(TCLOD_PC_PREFIX \"\${CMAKE_INSTALL_PREFIX}\")
set(TCLOD_PC_LIBDIR [==[${_tclod_pc_libdir}]==])
set(TCLOD_PC_INCLUDEDIR [==[${_tclod_pc_includedir}]==])
set(TCLOD_PC_VERSION [==[${PROJECT_VERSION}]==])
set(TCLOD_PC_DESCRIPTION [==[${PROJECT_DESCRIPTION}]==])
set(TCLOD_PC_CFLAGS [==[${_tclod_pc_cflags}]==])
set(TCLOD_PC_LIBS [==[${_tclod_pc_libs}]==])
set(TCLOD_PC_LIBS_PRIVATE [==[${_tclod_pc_libs_private}]==])
configure_file([==[${CMAKE_CURRENT_LIST_DIR}/tclod.pc.in]==]
               [==[${PROJECT_BINARY_DIR}/tclod.pc]==] @ONLY)
")
install(FILES ${PROJECT_BINARY_DIR}/tclod.pc
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

unset(_tclod_pc_libdir)
unset(_tclod_pc_includedir)
unset(_tclod_pc_cflags)
unset(_tclod_pc_libm)
unset(_tclod_pc_libs)
unset(_tclod_pc_libs_private)
