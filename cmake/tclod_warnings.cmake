# Per-target compiler settings shared by every target of the project.

# tclod_set_warnings(<target> [STRICT])
#   Warnings for a target; STRICT adds the conversion warnings the library keeps.
#   The prototype warnings, which only C has, go to C sources alone, so that a C++
#   target (examples/minimal.cpp) takes the same call.
function(tclod_set_warnings target)
  cmake_parse_arguments(ARG "STRICT" "" "" ${ARGN})
  if(CMAKE_C_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE
      -Wall -Wextra -Wpedantic -Wshadow
      $<$<COMPILE_LANGUAGE:C>:-Wstrict-prototypes>
      $<$<COMPILE_LANGUAGE:C>:-Wmissing-prototypes>
      -Wpointer-arith -Wcast-qual -Wformat=2 -Wundef -Wvla -Wwrite-strings)
    if(ARG_STRICT)
      target_compile_options(${target} PRIVATE -Wconversion -Wsign-conversion
        -Wdouble-promotion -Wcast-align)
    endif()
    if(TCLOD_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  elseif(MSVC)
    target_compile_options(${target} PRIVATE /W4 $<$<BOOL:${TCLOD_WERROR}>:/WX>)
  endif()
  tclod_set_sanitizers(${target})
endfunction()

# tclod_set_sanitizers(<target>): applies TCLOD_SANITIZE to compile and link.
function(tclod_set_sanitizers target)
  if(TCLOD_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=${TCLOD_SANITIZE}
      -fno-sanitize-recover=all -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=${TCLOD_SANITIZE})
  endif()
endfunction()
