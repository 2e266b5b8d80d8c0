# Regenerates a docs page with `kagec docs` and fails if the committed copy differs.
execute_process(COMMAND ${KAGEC} docs ${DOC} OUTPUT_FILE ${FRESH} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kagec docs ${DOC} failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${COMMITTED} ${FRESH} RESULT_VARIABLE diff)
if(NOT diff EQUAL 0)
  message(FATAL_ERROR "${COMMITTED} is stale: run `kagec docs ${DOC} > ${COMMITTED}`")
endif()
