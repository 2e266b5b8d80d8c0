# Installs the build into PREFIX, checks that the installed kagec loads no library from the build tree,
# then, with the installed kagec only:
#  1. proves that generated sources include the installed headers: with an #error planted in
#     PREFIX/share/kagec/runtime/kage_hd.h, `kagec compile` must fail on exactly that line;
#  2. compiles CONFIG for the CPU (kernels_host.so built against the installed headers) and runs the
#     compiled directory with EXAMPLE, which must print what it prints for the YAML itself;
#  3. renders CONFIG with the installed kagec.
#   cmake -DBUILD=dir -DPREFIX=dir -DEXAMPLE=exe -DCONFIG=file -DOUT=dir -P install_test.cmake
file(REMOVE_RECURSE ${PREFIX} ${OUT})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${PREFIX} RESULT_VARIABLE rc OUTPUT_QUIET
                ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed: ${err}")
endif()
set(kagec ${PREFIX}/bin/kagec)
set(header ${PREFIX}/share/kagec/runtime/kage_hd.h)
if(NOT EXISTS ${kagec} OR NOT EXISTS ${header})
  message(FATAL_ERROR "the install lacks ${kagec} or ${header}")
endif()
unset(ENV{KAGE_ROOT})

# The build tree may be removed after an install: no shared library of the installed kagec may resolve there.
file(GET_RUNTIME_DEPENDENCIES EXECUTABLES ${kagec} RESOLVED_DEPENDENCIES_VAR resolved
     UNRESOLVED_DEPENDENCIES_VAR unresolved)
if(unresolved)
  message(FATAL_ERROR "the installed kagec needs libraries that are not found: ${unresolved}")
endif()
foreach(library ${resolved})
  string(FIND "${library}" "${BUILD}/" at)
  if(at EQUAL 0)
    message(FATAL_ERROR "the installed kagec loads ${library} from the build tree: install that library too")
  endif()
endforeach()

file(READ ${header} original)
file(WRITE ${header} "#error kage-install-test: the installed header was used\n${original}")
execute_process(COMMAND ${kagec} compile ${CONFIG} -o ${OUT}/planted --no-gpu RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(WRITE ${header} "${original}")
if(rc EQUAL 0 OR NOT err MATCHES "kage-install-test: the installed header was used")
  message(FATAL_ERROR "the installed kagec did not compile against ${header} (exit ${rc}):\n${err}")
endif()

execute_process(COMMAND ${kagec} compile ${CONFIG} -o ${OUT}/compiled --no-gpu RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed kagec could not compile ${CONFIG}:\n${err}")
endif()
execute_process(COMMAND ${EXAMPLE} ${CONFIG} RESULT_VARIABLE rc1 OUTPUT_VARIABLE yaml ERROR_VARIABLE e1)
execute_process(COMMAND ${EXAMPLE} ${OUT}/compiled RESULT_VARIABLE rc2 OUTPUT_VARIABLE compiled ERROR_VARIABLE e2)
if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0 OR yaml STREQUAL "" OR NOT yaml STREQUAL compiled)
  message(FATAL_ERROR "the installed kagec's compile disagrees with the YAML:\n${yaml}\n${compiled}\n${e1}${e2}")
endif()

execute_process(COMMAND ${kagec} render ${CONFIG} --steps 10 --every 5 --gif ${OUT}/run.gif RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "rendered 3 frames")
  message(FATAL_ERROR "the installed kagec could not render ${CONFIG}:\n${out}${err}")
endif()
message(STATUS "installed kagec: compiled and ran ${CONFIG}: ${compiled}")
