# SPDX-License-Identifier: GPL-2.0-or-later
# One check of the skips (tests/skips/CMakeLists.txt):
#   cmake -DBUILD_DIR=<build> -DTEST_NAME=<ctest name> -DCASE=<skipped|no_skip|no_match> -P skip_check.cmake
#   cmake -DBUILD_DIR=<build> -DSOURCE_DIR=<source> -DCASE=missing_tool -P skip_check.cmake
# Reads the registered test's command and properties from ctest itself, runs the command as ctest would (in its
# working directory) with Xvnc hidden, and checks its exit status and words. Fails with a message on a mismatch.

function(fail what)
  message(FATAL_ERROR "skip check '${CASE}': ${what}")
endfunction()

# Runs `command` (a list) in `dir` with the environment changes `env` (cmake -E env arguments); sets
# <prefix>_status and <prefix>_output (stdout and stderr together).
function(run_with prefix dir env)
  execute_process(COMMAND "${CMAKE_COMMAND}" -E env ${env} ${ARGN}
                  WORKING_DIRECTORY "${dir}" RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE output
                  TIMEOUT 50)
  set(${prefix}_status "${status}" PARENT_SCOPE)
  set(${prefix}_output "${output}" PARENT_SCOPE)
endfunction()

set(marker "RFBSIM-SKIPPED:")
set(hidden_xvnc "/nonexistent/rfbsim-skip-check/Xvnc")

if(CASE STREQUAL "missing_tool")
  set(why "frobnicator 3 not found (apt-get install frobnicator)")
  set(command "${CMAKE_COMMAND}" "-DWHY=${why}" -P "${SOURCE_DIR}/cmake/report_missing_test.cmake")
  run_with(plain "${BUILD_DIR}" "--unset=RFBSIM_NO_SKIP" ${command})
  if(NOT plain_status EQUAL 0 OR NOT plain_output MATCHES "${marker} frobnicator 3 not found")
    fail("expected exit 0 and '${marker} ${why}', got ${plain_status}: ${plain_output}")
  endif()
  run_with(strict "${BUILD_DIR}" "RFBSIM_NO_SKIP=1" ${command})
  if(strict_status EQUAL 0 OR strict_output MATCHES "${marker}" OR NOT strict_output MATCHES "frobnicator 3 not found")
    fail("expected a failure naming the tool under RFBSIM_NO_SKIP=1, got ${strict_status}: ${strict_output}")
  endif()
  return()
endif()

# The test as ctest knows it: its command, working directory and SKIP_REGULAR_EXPRESSION.
string(REGEX REPLACE "([][.*+?^$()|\\])" "\\\\\\1" name_regex "${TEST_NAME}")
execute_process(COMMAND "${CMAKE_CTEST_COMMAND}" -N --show-only=json-v1 -R "^${name_regex}$"
                WORKING_DIRECTORY "${BUILD_DIR}" RESULT_VARIABLE status OUTPUT_VARIABLE json)
if(NOT status EQUAL 0)
  fail("ctest -N could not list the tests")
endif()
string(JSON count LENGTH "${json}" tests)
if(NOT count EQUAL 1)
  fail("expected one registered test named '${TEST_NAME}', found ${count}")
endif()
string(JSON length LENGTH "${json}" tests 0 command)
set(command "")
math(EXPR last "${length} - 1")
foreach(i RANGE ${last})
  string(JSON part GET "${json}" tests 0 command ${i})
  list(APPEND command "${part}")
endforeach()
set(dir "${BUILD_DIR}")
set(skip_regex "")
string(JSON properties LENGTH "${json}" tests 0 properties)
math(EXPR last "${properties} - 1")
foreach(i RANGE ${last})
  string(JSON property GET "${json}" tests 0 properties ${i} name)
  if(property STREQUAL "WORKING_DIRECTORY")
    string(JSON dir GET "${json}" tests 0 properties ${i} value)
  elseif(property STREQUAL "SKIP_REGULAR_EXPRESSION")
    string(JSON skip_regex GET "${json}" tests 0 properties ${i} value 0)
  endif()
endforeach()
if(NOT skip_regex STREQUAL marker)
  fail("the test's SKIP_REGULAR_EXPRESSION is '${skip_regex}', not '${marker}': ctest would not show a skip")
endif()

if(CASE STREQUAL "skipped")
  run_with(run "${dir}" "--unset=RFBSIM_NO_SKIP;RFBSIM_XVNC=${hidden_xvnc}" ${command})
  if(NOT run_status EQUAL 0 OR NOT run_output MATCHES "${skip_regex}[^\n]*${hidden_xvnc}")
    fail("expected exit 0 and a '${marker}' line naming ${hidden_xvnc}, got ${run_status}: ${run_output}")
  endif()
elseif(CASE STREQUAL "no_skip")
  run_with(run "${dir}" "RFBSIM_NO_SKIP=1;RFBSIM_XVNC=${hidden_xvnc}" ${command})
  if(run_status EQUAL 0 OR run_output MATCHES "${skip_regex}" OR NOT run_output MATCHES "${hidden_xvnc}")
    fail("expected a failure naming ${hidden_xvnc} and no skip line, got ${run_status}: ${run_output}")
  endif()
elseif(CASE STREQUAL "no_match")
  # The same command with a name no test case has: the half a ';' in a name would leave.
  list(LENGTH command parts)
  if(parts LESS 2)
    fail("'${TEST_NAME}' has no test case name argument")
  endif()
  list(REMOVE_AT command 1)
  list(INSERT command 1 "no test case has this name")
  run_with(run "${dir}" "--unset=RFBSIM_NO_SKIP" ${command})
  if(run_status EQUAL 0)
    fail("a name that matches no test case passed: ${run_output}")
  endif()
else()
  fail("unknown CASE")
endif()
