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

# pkg-config finds the scratch prefix, not the configure-time one: the .pc names its prefix relative to itself.
set(ENV{PKG_CONFIG_PATH} "${prefix}/lib/pkgconfig")
file(REAL_PATH "${prefix}" real_prefix)
foreach(variable_dir IN ITEMS "prefix=" "libdir=/lib" "includedir=/include")
  string(REPLACE "=" ";" parts "${variable_dir}")
  list(GET parts 0 variable)
  list(LENGTH parts count)
  set(suffix "")
  if(count GREATER 1)
    list(GET parts 1 suffix)
  endif()
  run_step("pkg-config --variable=${variable}" pkg-config --variable=${variable} rfbsim)
  string(STRIP "${step_output}" given)
  if(NOT IS_DIRECTORY "${given}")
    message(FATAL_ERROR "pkg-config's ${variable} is not a directory: '${given}'")
  endif()
  file(REAL_PATH "${given}" real_given)
  if(NOT real_given STREQUAL "${real_prefix}${suffix}")
    message(FATAL_ERROR "pkg-config's ${variable} is '${given}', not in the install prefix ${prefix}")
  endif()
endforeach()
run_step("pkg-config" pkg-config --libs --cflags rfbsim)
string(FIND "${step_output}" "-lrfbsim" at)
if(at EQUAL -1)
  message(FATAL_ERROR "pkg-config gave no -lrfbsim: ${step_output}")
endif()

# examples/minimal again, as a project without CMake would build it: the compiler and pkg-config's flags only.
run_step("pkg-config flags" pkg-config --cflags --libs rfbsim opengl)
string(STRIP "${step_output}" pc_flags)
separate_arguments(pc_flags UNIX_COMMAND "${pc_flags}")
set(pc_example "${WORK_DIR}/minimal_pkgconfig/rfbsim_minimal")
file(MAKE_DIRECTORY "${WORK_DIR}/minimal_pkgconfig")
run_step("build examples/minimal with pkg-config" ${CXX} -o "${pc_example}" "${SOURCE_DIR}/examples/minimal/main.cpp"
         ${pc_flags})

# Each build starts, binds a free port and says where it serves; `timeout` ends it.
function(check_serves what program)
  execute_process(COMMAND timeout --preserve-status -s INT 3 ${program} 0 RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  string(REGEX MATCH "serving .* on vnc://127.0.0.1:[0-9]+" served "${out}")
  if(NOT served)
    message(FATAL_ERROR "${what} did not serve (rc ${rc}):\n${out}\n${err}")
  endif()
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} did not exit cleanly on SIGINT (rc ${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ${served}")
endfunction()
file(GLOB_RECURSE example "${WORK_DIR}/minimal/rfbsim_minimal")
check_serves("rfbsim_minimal (find_package)" "${example}")
# The pkg-config build has no run path into the scratch prefix: the loader is told where the library is.
set(ENV{LD_LIBRARY_PATH} "${prefix}/lib")
check_serves("rfbsim_minimal (pkg-config)" "${pc_example}")
