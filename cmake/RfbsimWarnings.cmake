# SPDX-License-Identifier: GPL-2.0-or-later
# rfbsim_warnings(<target>): the warning set every rfbsim target compiles with.
function(rfbsim_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
    -Wcast-align -Woverloaded-virtual -Wconversion -Wsign-conversion -Wnull-dereference
    -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough
    # In a unity batch a .cpp is included, not the main file, so GCC takes a pimpl's fields of file-local types
    # for a header's and warns; built alone the same file is clean. (GCC's C++ warning only.)
    $<$<AND:$<CXX_COMPILER_ID:GNU>,$<COMPILE_LANGUAGE:CXX>,$<BOOL:$<TARGET_PROPERTY:${target},UNITY_BUILD>>>:-Wno-subobject-linkage>)
endfunction()
