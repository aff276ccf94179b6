# Warning flags applied to every target of this project (never exported).
# -Wno-restrict: GCC 12 reports false -Wrestrict overlaps inside
# std::string's operator+ at -O3 (GCC bug 105651).
add_library(pdp_warnings INTERFACE)
target_compile_options(pdp_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion>
  $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>
  $<$<AND:$<BOOL:${PDP_WARNINGS_AS_ERRORS}>,$<CXX_COMPILER_ID:GNU,Clang>>:-Werror>)
