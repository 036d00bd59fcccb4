# SPDX-License-Identifier: GPL-2.0-or-later
# With RFBSIM_SANITIZE=ON every target is built with ASan + UBSan, and UBSan findings abort,
# so that the whole test suite fails on the first report instead of printing and carrying on.
if(RFBSIM_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
