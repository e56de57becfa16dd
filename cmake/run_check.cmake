# Runs one command and checks how it ended, for the tests of the programs
# (tests/tiles, examples/, the --help of every program):
#   cmake -DRUN=<program>|<arg>|... -DEXPECT_EXIT=<code>
#         [-DEXPECT_STDOUT=<regex>] [-DEXPECT_STDOUT_ALSO=<regex>]
#         [-DEXPECT_STDERR=<regex>] [-DEXPECT_STDOUT_WORDS=<word>|<word>|...]
#         [-DCHECK_FILE=<path> -DCHECK_FILE_REGEX=<regex>]
#         [-DCLEAN_DIR=<dir>] -P run_check.cmake
# CLEAN_DIR is removed first, so that a generator starts from nothing.
# EXPECT_STDOUT_WORDS: stdout must hold each word whole (not inside a longer
# name such as --frames for frames), each after the one before it; the words
# may hold no regular-expression characters but '-' and ':'.
# The command's arguments are separated by '|', since ctest would split a ';'
# list into arguments of cmake itself.
string(REPLACE "|" ";" _command "${RUN}")
if(DEFINED CLEAN_DIR)
  file(REMOVE_RECURSE "${CLEAN_DIR}")
endif()
execute_process(COMMAND ${_command}
  RESULT_VARIABLE _exit
  OUTPUT_VARIABLE _out
  ERROR_VARIABLE _err)
set(_failed "")
if(NOT "${_exit}" STREQUAL "${EXPECT_EXIT}")
  string(APPEND _failed "exit status ${_exit}, expected ${EXPECT_EXIT}\n")
endif()
foreach(_pair "STDOUT;_out" "STDOUT_ALSO;_out" "STDERR;_err")
  list(GET _pair 0 _what)
  list(GET _pair 1 _text)
  if(DEFINED EXPECT_${_what} AND NOT "${${_text}}" MATCHES "${EXPECT_${_what}}")
    string(APPEND _failed "output does not match ${EXPECT_${_what}}\n")
  endif()
endforeach()
if(DEFINED EXPECT_STDOUT_WORDS)
  string(REPLACE "|" ";" _words "${EXPECT_STDOUT_WORDS}")
  set(_rest "${_out}")
  foreach(_word IN LISTS _words)
    string(REGEX MATCH "(^|[^A-Za-z0-9_-])${_word}([^A-Za-z0-9_]|$)" _hit "${_rest}")
    if(NOT _hit)
      string(APPEND _failed "output lacks '${_word}' after the words before it\n")
      break()
    endif()
    # go on from the hit's last character, which may start the next word's match
    string(FIND "${_rest}" "${_hit}" _at)
    string(LENGTH "${_hit}" _length)
    math(EXPR _at "${_at} + ${_length} - 1")
    string(SUBSTRING "${_rest}" ${_at} -1 _rest)
  endforeach()
endif()
if(DEFINED CHECK_FILE)
  if(NOT EXISTS "${CHECK_FILE}")
    string(APPEND _failed "${CHECK_FILE} was not written\n")
  else()
    file(READ "${CHECK_FILE}" _file)
    if(NOT "${_file}" MATCHES "${CHECK_FILE_REGEX}")
      string(APPEND _failed "${CHECK_FILE} does not match ${CHECK_FILE_REGEX}\n")
    endif()
  endif()
endif()
if(_failed)
  message(FATAL_ERROR "${RUN}\n${_failed}--- stdout:\n${_out}--- stderr:\n${_err}")
endif()
