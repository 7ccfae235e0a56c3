# Interface target carrying the project's warning flags; link it PRIVATE.
add_library(pixyslam_warnings INTERFACE)
target_compile_options(pixyslam_warnings INTERFACE
  $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow>)
