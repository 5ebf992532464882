# ctest's install check: `cmake --install` the build tree into a fresh prefix, then configure,
# build and run tests/install/consumer against it alone, as another project would.
# -D BUILD_DIR (this build), WORK_DIR (scratch), CONSUMER_DIR (the consumer's sources),
# SANITIZE_FLAGS (the build's sanitizer flags, ;-separated; empty: none), PYTHON and
# PYTHON_SITE (the Python module's interpreter and its directory under the prefix; empty: the
# module is not built).
function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${what} failed (${status}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok ${out}")
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run_step("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(file bin/oalservo include/oalservo/detector/detector.h share/oalservo/config/servo-sim.yaml)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "install did not write ${prefix}/${file}")
  endif()
endforeach()
run_step("installed oalservo --version" ${prefix}/bin/oalservo --version)
if(PYTHON)
  run_step("installed Python module"
           ${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/${PYTHON_SITE} PYTHONDONTWRITEBYTECODE=1
           ${PYTHON} -c "import oalservo; print(oalservo.Target.builtin('four-line-a3').name)")
endif()
# A sanitized library links only into a program built with the same sanitizers.
string(REPLACE ";" " " sanitize "${SANITIZE_FLAGS}")
run_step("consumer configure" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/build
         -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix}
         "-DCMAKE_CXX_FLAGS=${sanitize}" "-DCMAKE_EXE_LINKER_FLAGS=${sanitize}")
run_step("consumer build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run_step("consumer run" ${WORK_DIR}/build/consumer)
