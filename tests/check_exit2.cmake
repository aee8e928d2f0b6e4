# Runs `EXE render SCENE [ARGS]` and requires exit code 2 and the expected one-line message on
# stderr (ARGS: a ;-list of extra options).
#   cmake -DEXE=<canopy> -DSCENE=<file> [-DEXPECT=<message>] [-DARGS=<a;b>] -P check_exit2.cmake
# Options:
#   -DTIMEOUT=<s>      fail if canopy runs longer (default 60; hang tests use a few seconds)
#   -DENV=<A=1;B=2>    environment for canopy
#   -DMKFIFO=ON        SCENE is (re)created as a FIFO first (nothing ever writes to it)
#   -DSPARSE=<bytes>   SCENE is (re)created as a sparse file of that size first
#   -DPREFIX=ON        EXPECT is the start of the message (machine-dependent numbers follow); the
#                      message must still be the only line on stderr
# Without EXPECT, the message is "<SCENE>: " followed by the text of the scene file's first line
# "// expect: <text>" ("{dir}" in it stands for the scene file's directory).
if(NOT DEFINED EXE OR NOT DEFINED SCENE)
  message(FATAL_ERROR "usage: cmake -DEXE=... -DSCENE=... [-DEXPECT=...] -P check_exit2.cmake")
endif()

# Lists may be written with "|" instead of ";" (add_test wrappers split on ";").
foreach(v ARGS FILES MAGIC ENV)
  if(DEFINED ${v})
    string(REPLACE "|" ";" ${v} "${${v}}")
  endif()
endforeach()
if(NOT DEFINED TIMEOUT)
  set(TIMEOUT 60)
endif()
if(MKFIFO)
  file(REMOVE "${SCENE}")
  execute_process(COMMAND mkfifo "${SCENE}" RESULT_VARIABLE mk)
  if(NOT mk STREQUAL "0")
    message(FATAL_ERROR "mkfifo ${SCENE} failed")
  endif()
endif()
if(DEFINED SPARSE)
  file(REMOVE "${SCENE}")
  execute_process(COMMAND truncate -s "${SPARSE}" "${SCENE}" RESULT_VARIABLE mk)
  if(NOT mk STREQUAL "0")
    message(FATAL_ERROR "truncate ${SCENE} failed")
  endif()
endif()

if(NOT DEFINED EXPECT)
  file(READ "${SCENE}" text)
  string(REGEX MATCH "^// expect: ([^\n]*)" line "${text}")
  if(NOT line)
    message(FATAL_ERROR "${SCENE} has no '// expect: ' first line")
  endif()
  set(suffix "${CMAKE_MATCH_1}")
  get_filename_component(dir "${SCENE}" DIRECTORY)
  string(REPLACE "{dir}" "${dir}" suffix "${suffix}")
  set(EXPECT "${SCENE}: ${suffix}")
endif()

execute_process(
  COMMAND ${CMAKE_COMMAND} -E env ${ENV} "${EXE}" render "${SCENE}" ${ARGS}
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err
  TIMEOUT ${TIMEOUT})
if(MKFIFO OR DEFINED SPARSE)
  file(REMOVE "${SCENE}")
endif()

if(NOT rc STREQUAL "2")
  message(FATAL_ERROR "expected exit code 2, got '${rc}'\nstderr:\n${err}\nstdout:\n${out}")
endif()
string(FIND "${err}" "${EXPECT}" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "stderr does not contain the expected message\nexpected: ${EXPECT}\n"
                      "stderr:\n${err}")
endif()
if(PREFIX)
  # Only the message: one line, nothing before it and nothing after its line break.
  string(REGEX REPLACE "\n$" "" body "${err}")
  string(FIND "${body}" "\n" nl)
  if(NOT pos EQUAL 0 OR NOT nl EQUAL -1)
    message(FATAL_ERROR "stderr is not the message alone on one line\nstderr:\n${err}")
  endif()
  return()
endif()
# The message is one line: nothing but a line break may follow it.
string(LENGTH "${EXPECT}" len)
math(EXPR after "${pos} + ${len}")
string(SUBSTRING "${err}" ${after} 1 next)
if(NOT next STREQUAL "" AND NOT next STREQUAL "\n" AND NOT next STREQUAL "\r")
  message(FATAL_ERROR "the message continues on the same line\nstderr:\n${err}")
endif()
