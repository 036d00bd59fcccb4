# SPDX-License-Identifier: GPL-2.0-or-later
# Script for the install test (cmake -P): every step must succeed, or the test fails with its output.
function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}${err}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run_step("cmake --install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
foreach(expected include/rfbsim/server.hpp include/rfbsim/offscreen_gl.hpp lib/cmake/rfbsim/rfbsimConfig.cmake
                 lib/pkgconfig/rfbsim.pc share/rfbsim/web/index.html bin/sim_rfb)
  file(GLOB_RECURSE found "${prefix}/*")
  string(FIND "${found}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the install lacks ${expected}")
  endif()
endforeach()

# A third-party project: only the installed package, no source tree.
run_step("configure examples/minimal" ${CMAKE_COMMAND} -S "${SOURCE_DIR}/examples/minimal" -B "${WORK_DIR}/minimal"
         -G "${GENERATOR}" "-DCMAKE_PREFIX_PATH=${prefix}")
run_step("build examples/minimal" ${CMAKE_COMMAND} --build "${WORK_DIR}/minimal")

# pkg-config sees the same library.
set(ENV{PKG_CONFIG_PATH} "${prefix}/lib/pkgconfig")
run_step("pkg-config" pkg-config --libs --cflags rfbsim)
string(FIND "${step_output}" "-lrfbsim" at)
if(at EQUAL -1)
  message(FATAL_ERROR "pkg-config gave no -lrfbsim: ${step_output}")
endif()

# The example starts, binds a free port and says where it serves; `timeout` ends it.
file(GLOB_RECURSE example "${WORK_DIR}/minimal/rfbsim_minimal")
execute_process(COMMAND timeout --preserve-status -s INT 3 ${example} 0 RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "serving .* on vnc://127.0.0.1:[0-9]+" served "${out}")
if(NOT served)
  message(FATAL_ERROR "rfbsim_minimal did not serve (rc ${rc}):\n${out}\n${err}")
endif()
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "rfbsim_minimal did not exit cleanly on SIGINT (rc ${rc}):\n${out}\n${err}")
endif()
message(STATUS "${served}")
