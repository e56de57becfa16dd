# Writes libtclod as one source file, the whole library in a single translation
# unit (the SQLite pattern): <OUT>/tclod.c, and a copy of the public header as
# <OUT>/tclod/tclod.h so that the directory is all a host needs.
#
#   cmake -D OUT=<dir> -P cmake/amalgamate.cmake
#
# tclod.c is every private header of src/ (its layers' folders), each after
# the headers it includes (path order among those whose includes are placed),
# followed by every source of src/ in path order, each file's
# #include "<private header>" lines dropped; the public
# header stays a separate file that tclod.c includes. Static names must
# therefore be unique across src/ (a static function of one file would clash
# with its namesake in another): .ci/run compiles the result with -Werror to
# check.
if(NOT OUT)
  message(FATAL_ERROR "amalgamate.cmake: no output directory; run cmake -D OUT=<dir> -P ${CMAKE_CURRENT_LIST_FILE}")
endif()
get_filename_component(_root "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
get_filename_component(_out "${OUT}" ABSOLUTE BASE_DIR "${CMAKE_BINARY_DIR}")
set(_header "${_root}/include/tclod/tclod.h")

file(STRINGS "${_header}" _version_lines REGEX "^#define TCLOD_VERSION_(MAJOR|MINOR|PATCH) [0-9]+$")
set(_version "")
foreach(_line IN LISTS _version_lines)
  string(REGEX REPLACE "^#define TCLOD_VERSION_[A-Z]+ ([0-9]+)$" "\\1" _part "${_line}")
  string(APPEND _version ".${_part}")
endforeach()
string(SUBSTRING "${_version}" 1 -1 _version)

file(GLOB_RECURSE _sources RELATIVE "${_root}" "${_root}/src/*.c")
list(SORT _sources)

# The private headers in an order where each follows those it includes.
file(GLOB_RECURSE _pending RELATIVE "${_root}" "${_root}/src/*.h")
list(SORT _pending)
set(_headers "")
while(_pending)
  set(_placed "")
  foreach(_h IN LISTS _pending)
    file(STRINGS "${_root}/${_h}" _includes REGEX "^#include \"[./a-z_]+\\.h\"")
    get_filename_component(_dir "${_root}/${_h}" DIRECTORY)
    set(_ready 1)
    foreach(_line IN LISTS _includes)
      string(REGEX REPLACE "^#include \"([./a-z_]+\\.h)\".*$" "\\1" _dep "${_line}")
      get_filename_component(_dep "${_dir}/${_dep}" ABSOLUTE)
      if(NOT EXISTS "${_dep}")
        continue() # the public header, tclod/tclod.h, on the include path
      endif()
      file(RELATIVE_PATH _dep "${_root}" "${_dep}")
      list(FIND _headers "${_dep}" _at)
      if(_at EQUAL -1)
        set(_ready 0)
      endif()
    endforeach()
    if(_ready)
      list(APPEND _headers "${_h}")
      list(APPEND _placed "${_h}")
    endif()
  endforeach()
  if(NOT _placed)
    message(FATAL_ERROR "amalgamate.cmake: the includes of ${_pending} form a cycle or name a missing header")
  endif()
  list(REMOVE_ITEM _pending ${_placed})
endwhile()
set(_files ${_headers} ${_sources})

set(_text [=[/*
 * tclod.c: libtclod @VERSION@ in one file, generated from src/ by
 * cmake/amalgamate.cmake (cmake -D OUT=<dir> -P cmake/amalgamate.cmake).
 * Do not edit it: change src/ and generate it again.
 *
 * Compile it as C99 (or later) with tclod/tclod.h beside it or on the include
 * path, and link libm:
 *
 *     cc -std=c99 -O2 -ffp-contract=off -fno-fast-math -fno-math-errno \
 *        -fno-trapping-math -c tclod.c
 *     cc app.o tclod.o -lm
 *
 * The flags are those of the CMake build (GCC and Clang); put them after any
 * of the host's own. They are what keeps selections bit-identical across
 * compilers, optimisation levels and machines (docs/api.md, Determinism):
 *   -ffp-contract=off  no fused multiply-add: a*b + c rounded once instead of
 *                      twice gives other bits, and Clang (any -std) and GCC
 *                      (-std=gnu*, its default) fuse wherever the target has
 *                      FMA (-march=x86-64-v3, ARM64);
 *   -fno-fast-math     IEEE arithmetic and the checks for NaN and infinity on
 *                      the host's values, even in a -ffast-math build;
 *   -fno-math-errno    speed only (sqrt is one instruction): libtclod never
 *                      reads errno, and the results are the same;
 *   -fno-trapping-math speed only: libtclod never reads the floating-point
 *                      exception flags, and GCC may then compute both sides
 *                      of a select, as vectorising the batch projection's
 *                      loop needs (at -O3); the results are the same.
 * Without them the library still works and keeps its budget, but its
 * selections may differ in the last bits between builds.
 *
 * On Windows, define TCLOD_STATIC for tclod.c and for every file that
 * includes tclod/tclod.h (no DLL import or export).
 */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L /* clock_gettime, as src/core/alloc.c asks */
#endif
]=])
string(REPLACE "@VERSION@" "${_version}" _text "${_text}")

foreach(_file IN LISTS _files)
  file(READ "${_root}/${_file}" _body)
  # each private header is in tclod.c already, above this file
  string(REGEX REPLACE "\n#include \"((\\.\\./)+[a-z_/]+|[a-z_]+)\\.h\"" "" _body "${_body}")
  string(APPEND _text "\n/* ---- ${_file} ---- */\n${_body}")
endforeach()

file(WRITE "${_out}/tclod.c" "${_text}")
file(READ "${_header}" _body)
file(WRITE "${_out}/tclod/tclod.h" "${_body}")
