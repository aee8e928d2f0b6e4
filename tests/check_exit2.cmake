# Runs `EXE render SCENE [ARGS]` and requires exit code 2 and the expected one-line message on
# stderr (ARGS: a ;-list of extra options).
#   cmake -DEXE=<canopy> -DSCENE=<file> [-DEXPECT=<message>] [-DARGS=<a;b>] -P check_exit2.cmake
# Without EXPECT, the message is "<SCENE>: " followed by the text of the scene file's first line
# "// expect: <text>" ("{dir}" in it stands for the scene file's directory).
if(NOT DEFINED EXE OR NOT DEFINED SCENE)
  message(FATAL_ERROR "usage: cmake -DEXE=... -DSCENE=... [-DEXPECT=...] -P check_exit2.cmake")
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
  COMMAND "${EXE}" render "${SCENE}" ${ARGS}
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err
  TIMEOUT 60)

if(NOT rc STREQUAL "2")
  message(FATAL_ERROR "expected exit code 2, got '${rc}'\nstderr:\n${err}\nstdout:\n${out}")
endif()
string(FIND "${err}" "${EXPECT}" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "stderr does not contain the expected message\nexpected: ${EXPECT}\n"
                      "stderr:\n${err}")
endif()
# The message is one line: nothing but a line break may follow it.
string(LENGTH "${EXPECT}" len)
math(EXPR after "${pos} + ${len}")
string(SUBSTRING "${err}" ${after} 1 next)
if(NOT next STREQUAL "" AND NOT next STREQUAL "\n" AND NOT next STREQUAL "\r")
  message(FATAL_ERROR "the message continues on the same line\nstderr:\n${err}")
endif()
