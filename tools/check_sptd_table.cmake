# Runs fit-sptd and compares its output with the committed cl/bsdf/sptd_table.h byte for byte.
execute_process(COMMAND ${FIT} OUTPUT_FILE ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "fit-sptd failed: ${rc}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT} ${EXPECTED} RESULT_VARIABLE diff)
if(NOT diff EQUAL 0)
  message(FATAL_ERROR "${EXPECTED} differs from the output of fit-sptd (${OUT}): regenerate it")
endif()
