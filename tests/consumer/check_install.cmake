# Install the build tree into a scratch prefix, then configure, build and run tests/consumer
# against it; the installed `textile bench` runs too. Fails on any step.
# Args: BUILD_DIR, SOURCE_DIR, WORK_DIR.
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed: ${ARGN}\n${out}\n${err}")
  endif()
  set(LAST_OUTPUT "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
# The installed `textile bench` finds the installed textile-bench beside it.
run(${WORK_DIR}/prefix/bin/textile bench --list)
if(NOT LAST_OUTPUT MATCHES "hinge-curve\t")
  message(FATAL_ERROR "installed textile bench --list printed: ${LAST_OUTPUT}")
endif()
# A sanitizer build installs instrumented libraries; the consumer must link the runtime too.
set(flags "")
if(SANITIZE)
  set(flags "-fsanitize=${SANITIZE}")
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix
    -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS=${flags}" "-DCMAKE_EXE_LINKER_FLAGS=${flags}")
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/consumer)
if(NOT LAST_OUTPUT MATCHES "M\\(1/cm\\) = 0\\.09")
  message(FATAL_ERROR "consumer printed an unexpected value: ${LAST_OUTPUT}")
endif()
message(STATUS "consumer: ${LAST_OUTPUT}")
