# tclod_add_help_tests(<dir>...)
#   A test help_<target> for every executable defined in the given directories
#   and their subdirectories, so that a program added later is covered without
#   being listed: `<program> --help` must exit 0 and print its usage on stdout,
#   starting "usage: <target>" (run_check.cmake). Call it at the end of the top
#   directory, after the directories were added.
function(tclod_add_help_tests)
  foreach(_dir IN LISTS ARGN)
    get_property(_targets DIRECTORY ${_dir} PROPERTY BUILDSYSTEM_TARGETS)
    foreach(_target IN LISTS _targets)
      get_target_property(_type ${_target} TYPE)
      if(_type STREQUAL "EXECUTABLE")
        add_test(NAME help_${_target}
          COMMAND ${CMAKE_COMMAND} "-DRUN=$<TARGET_FILE:${_target}>|--help" -DEXPECT_EXIT=0
            "-DEXPECT_STDOUT=^usage: ${_target}( |\n)"
            -P ${PROJECT_SOURCE_DIR}/cmake/run_check.cmake)
      endif()
    endforeach()
    get_property(_subdirs DIRECTORY ${_dir} PROPERTY SUBDIRECTORIES)
    if(_subdirs)
      tclod_add_help_tests(${_subdirs})
    endif()
  endforeach()
endfunction()
