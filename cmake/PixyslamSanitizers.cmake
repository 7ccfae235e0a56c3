# Sanitizer and fuzzing builds. These are the one place with directory-wide
# flags: a sanitizer only works when every object (and the link) carries it.
#   -DPIXYSLAM_SANITIZE=address,undefined   ASan + UBSan (build-asan, preset "asan")
#   -DPIXYSLAM_SANITIZE=thread              TSan (build-tsan, preset "tsan")
#   -DPIXYSLAM_FUZZ=ON (Clang)              libFuzzer targets in tests/fuzz, with ASan + UBSan
set(PIXYSLAM_SANITIZE "" CACHE STRING "Sanitizers to build with: address,undefined | thread | empty for none")
option(PIXYSLAM_FUZZ "Build the libFuzzer targets (needs Clang and libclang-rt-14-dev)" OFF)

if(PIXYSLAM_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "PIXYSLAM_FUZZ needs Clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++")
  endif()
  if(NOT PIXYSLAM_SANITIZE)
    set(PIXYSLAM_SANITIZE "address,undefined" CACHE STRING "" FORCE)
  endif()
  # Coverage feedback for the code under test; the fuzz targets add -fsanitize=fuzzer.
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()

if(PIXYSLAM_SANITIZE)
  if(PIXYSLAM_SANITIZE MATCHES "thread" AND PIXYSLAM_SANITIZE MATCHES "address")
    message(FATAL_ERROR "PIXYSLAM_SANITIZE: thread cannot be combined with address")
  endif()
  # Line tables are all a sanitizer report needs; the fuzz build (Eigen-heavy
  # code compiled with ASan + UBSan) builds ~25 % faster with them than with -g.
  if(PIXYSLAM_FUZZ)
    add_compile_options(-fsanitize=${PIXYSLAM_SANITIZE} -fno-omit-frame-pointer -gline-tables-only)
  else()
    add_compile_options(-fsanitize=${PIXYSLAM_SANITIZE} -fno-omit-frame-pointer -g)
  endif()
  add_link_options(-fsanitize=${PIXYSLAM_SANITIZE})
  if(PIXYSLAM_SANITIZE MATCHES "undefined")
    # A UBSan finding fails the test instead of scrolling past.
    add_compile_options(-fno-sanitize-recover=undefined)
  endif()
endif()
