# SPDX-License-Identifier: GPL-2.0-or-later
# How tests join ctest (docs/development.md, "Skips" and "How ctest shares the cores"):
#
#   rfbsim_add_catch_tests(<target> PREFIX <text> [SPEC <catch test spec>] [CPU <percent>]
#                          [ALL_ALIKE [COST <seconds>]] [PROPERTIES <name> <value>...])
#     Every TEST_CASE of the Catch2 executable <target> becomes the ctest test "<PREFIX><name>". A test that
#     cannot run its real part here says so (RFBSIM_SKIP, tests/support/skip.hpp) and ctest shows it Skipped;
#     a ctest name that matches no test case fails (--warn NoTests) instead of passing with nothing run.
#     Test case names must not contain ';' (a CMake list separator: the name would be cut in two).
#     CPU is how much of one core, in percent, a test of the executable typically keeps busy (default 100);
#     two tags on a test case say otherwise for it:
#       [waits]  it takes seconds and spends them waiting (a timeout, a backoff, a minute of streaming): 5
#       [busy]   it keeps most of a core busy for seconds (long simulations, floods of clients): 80
#     Both tags also mark a test as long, so that ctest starts it early (COST) instead of last. ALL_ALIKE: the
#     tags are not looked at, every test of SPEC takes CPU and, where given, COST.
#
#   rfbsim_add_missing_test(<name> WHY <text> [LABELS <label>...])
#     Registers <name> where the test cannot even be built or set up here (a program, a package or an npm
#     module is missing): Skipped with WHY, so that a partial machine lists it rather than forgets it.
#
#   rfbsim_test_load(<test>... CPU <percent> [COST <seconds>] [BROWSER])
#     The same accounting for tests added with add_test: CPU as above, COST its usual seconds, BROWSER for a
#     test that drives a browser (Chromium or Firefox): at most RFBSIM_BROWSERS_AT_ONCE of them run at once, and
#     they start before every other test (COST + 200), since two lanes of them are the run's longest chain.
#
# With RFBSIM_NO_SKIP=1 in the environment (scripts/test.sh and CI set it: they install everything the tests
# need) every skip fails instead, naming what is missing.
#
# Packing: every test holds RESOURCE_GROUPS "cpu:<percent>" of a pool of 100 per core (ctest-resources.json,
# written here and named by CTEST_RESOURCE_SPEC_FILE), so `ctest -j <many>` runs waiting tests side by side
# while tests that compute never ask for more cores than the machine has. A plain `ctest -j 2` uses the same
# pool and simply runs no more than two tests at a time.

# The start of a skip's line; tests/support/skip.hpp's kSkipMarker is the same text.
set(RFBSIM_SKIP_MARKER "RFBSIM-SKIPPED:")
set(RFBSIM_WAITS_CPU 5)
set(RFBSIM_WAITS_COST 60)
set(RFBSIM_BUSY_CPU 80)
set(RFBSIM_BUSY_COST 50)
# Chromium tests at once: each is a browser, a renderer and a simulator, 0.4 of a core on average.
set(RFBSIM_BROWSERS_AT_ONCE 2)

cmake_host_system_information(RESULT _rfbsim_cores QUERY NUMBER_OF_LOGICAL_CORES)
math(EXPR _rfbsim_cpu_slots "${_rfbsim_cores} * 100")
set(RFBSIM_CTEST_RESOURCES "${PROJECT_BINARY_DIR}/ctest-resources.json")
file(WRITE "${RFBSIM_CTEST_RESOURCES}"
     "{\"version\": {\"major\": 1, \"minor\": 0},\n"
     " \"local\": [{\"cpu\": [{\"id\": \"cores\", \"slots\": ${_rfbsim_cpu_slots}}],\n"
     "            \"chromium\": [{\"id\": \"browsers\", \"slots\": ${RFBSIM_BROWSERS_AT_ONCE}}]}]}\n")
set(CTEST_RESOURCE_SPEC_FILE "${RFBSIM_CTEST_RESOURCES}")

# Whether any source of `target` tags a test case with `tag` (e.g. "[waits]").
function(_rfbsim_sources_use_tag target tag out_var)
  get_target_property(sources ${target} SOURCES)
  get_target_property(source_dir ${target} SOURCE_DIR)
  foreach(source IN LISTS sources)
    if(NOT IS_ABSOLUTE "${source}")
      set(source "${source_dir}/${source}")
    endif()
    if(EXISTS "${source}")
      file(READ "${source}" text)
      string(FIND "${text}" "${tag}" at)
      if(at GREATER -1)
        set(${out_var} TRUE PARENT_SCOPE)
        return()
      endif()
    endif()
  endforeach()
  set(${out_var} FALSE PARENT_SCOPE)
endfunction()

function(rfbsim_add_catch_tests target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "ALL_ALIKE" "PREFIX;SPEC;CPU;COST" "PROPERTIES")
  if(NOT DEFINED arg_CPU)
    set(arg_CPU 100)
  endif()
  set(common TEST_PREFIX "${arg_PREFIX}" EXTRA_ARGS --warn NoTests)
  set(properties SKIP_REGULAR_EXPRESSION "${RFBSIM_SKIP_MARKER}" ${arg_PROPERTIES})
  set(plain_cost "")
  if(DEFINED arg_COST)
    set(plain_cost COST ${arg_COST})
  endif()
  set(has_waits FALSE)
  set(has_busy FALSE)
  if(NOT arg_ALL_ALIKE)
    _rfbsim_sources_use_tag(${target} "[waits]" has_waits)
    _rfbsim_sources_use_tag(${target} "[busy]" has_busy)
  endif()
  # One listing per kind of test (Catch specs: juxtaposed patterns must all hold, ~ negates).
  set(plain "${arg_SPEC}")
  if(has_waits)
    string(APPEND plain "~[waits]")
    catch_discover_tests(${target} TEST_SPEC "${arg_SPEC}[waits]" ${common} PROPERTIES ${properties}
                         RESOURCE_GROUPS "cpu:${RFBSIM_WAITS_CPU}" COST ${RFBSIM_WAITS_COST})
  endif()
  if(has_busy)
    string(APPEND plain "~[busy]")
    catch_discover_tests(${target} TEST_SPEC "${arg_SPEC}[busy]~[waits]" ${common} PROPERTIES ${properties}
                         RESOURCE_GROUPS "cpu:${RFBSIM_BUSY_CPU}" COST ${RFBSIM_BUSY_COST})
  endif()
  set(spec_args "")
  if(NOT plain STREQUAL "")
    set(spec_args TEST_SPEC "${plain}")
  endif()
  catch_discover_tests(${target} ${spec_args} ${common} PROPERTIES ${properties} RESOURCE_GROUPS "cpu:${arg_CPU}"
                       ${plain_cost})
endfunction()

function(rfbsim_test_load)
  cmake_parse_arguments(PARSE_ARGV 0 arg "BROWSER" "CPU;COST" "")
  set(resources "cpu:${arg_CPU}")
  if(arg_BROWSER)
    string(APPEND resources ",chromium:1")
  endif()
  set(properties RESOURCE_GROUPS "${resources}")
  if(arg_BROWSER)
    # The browser tests, two at a time, are the run's longest chain: they start before everything else.
    math(EXPR arg_COST "200 + 0${arg_COST}")
  endif()
  if(DEFINED arg_COST)
    list(APPEND properties COST ${arg_COST})
  endif()
  set_tests_properties(${arg_UNPARSED_ARGUMENTS} PROPERTIES ${properties})
endfunction()

function(rfbsim_add_missing_test name)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "WHY" "LABELS")
  add_test(NAME "${name}"
           COMMAND "${CMAKE_COMMAND}" "-DWHY=${arg_WHY}" -P "${PROJECT_SOURCE_DIR}/cmake/report_missing_test.cmake")
  set_tests_properties("${name}" PROPERTIES SKIP_REGULAR_EXPRESSION "${RFBSIM_SKIP_MARKER}" TIMEOUT 30
                                            RESOURCE_GROUPS "cpu:10")
  if(arg_LABELS)
    set_tests_properties("${name}" PROPERTIES LABELS "${arg_LABELS}")
  endif()
endfunction()
