# Renders tests/data/film_overflow.json (every pixel beyond FLT_MAX) and requires: exit 0, exactly
# one warning line on stderr naming the 16 pixels, "overflowed_pixels": 16 and no non-finite
# samples in the stats JSON, and an image whose values are all finite (checked by `canopy compare`
# against itself: it reports non-finite values).
#   cmake -DEXE=<canopy> -DSCENE=<file> -DWORK=<dir> -P check_film_overflow.cmake
if(NOT DEFINED EXE OR NOT DEFINED SCENE OR NOT DEFINED WORK)
  message(FATAL_ERROR "usage: cmake -DEXE=... -DSCENE=... -DWORK=... -P check_film_overflow.cmake")
endif()
file(MAKE_DIRECTORY "${WORK}")
execute_process(
  COMMAND "${EXE}" render "${SCENE}" --out "${WORK}/overflow.exr" --stats-json
          "${WORK}/overflow.json"
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err
  TIMEOUT 120)
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "expected exit code 0, got '${rc}'\nstderr:\n${err}")
endif()
string(REGEX MATCHALL "warning[^\n]*" warnings "${err}")
list(LENGTH warnings n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one warning line, got ${n}\nstderr:\n${err}")
endif()
string(FIND "${warnings}" "16 pixels exceed the float range" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "the warning does not name the 16 pixels: ${warnings}")
endif()
file(READ "${WORK}/overflow.json" stats)
string(JSON over ERROR_VARIABLE e1 GET "${stats}" overflowed_pixels)
string(JSON nonfinite ERROR_VARIABLE e2 GET "${stats}" nonfinite_samples)
if(NOT over STREQUAL "16" OR NOT nonfinite STREQUAL "0")
  message(FATAL_ERROR "stats: overflowed_pixels '${over}' (${e1}), nonfinite_samples "
                      "'${nonfinite}' (${e2}); expected 16 and 0")
endif()
execute_process(
  COMMAND "${EXE}" compare "${WORK}/overflow.exr" "${WORK}/overflow.exr"
  RESULT_VARIABLE rc2
  OUTPUT_VARIABLE cmp
  ERROR_VARIABLE cmp_err
  TIMEOUT 60)
if(NOT rc2 STREQUAL "0" OR cmp MATCHES "non-finite")
  message(FATAL_ERROR "the image has non-finite values or cannot be compared:\n${cmp}${cmp_err}")
endif()
