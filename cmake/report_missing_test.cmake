# SPDX-License-Identifier: GPL-2.0-or-later
# The command of a test that cannot run here (rfbsim_add_missing_test): cmake -DWHY=<text> -P this file.
# Prints the skip marker with WHY (ctest shows the test Skipped), or fails under RFBSIM_NO_SKIP=1.
if("$ENV{RFBSIM_NO_SKIP}" STREQUAL "1")
  message(FATAL_ERROR "cannot run here (RFBSIM_NO_SKIP=1): ${WHY}")
endif()
message("RFBSIM-SKIPPED: ${WHY}")
