# Regenerates spec_fields.h and fails if the committed copy differs.
execute_process(COMMAND ${GEN} ${SCHEMA} ${FRESH} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kage_schemagen failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${COMMITTED} ${FRESH} RESULT_VARIABLE diff)
if(NOT diff EQUAL 0)
  message(FATAL_ERROR "${COMMITTED} is stale: rebuild and copy ${FRESH} over it (kage_schemagen SCHEMA OUT)")
endif()
