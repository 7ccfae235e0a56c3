# Cross-building for the Raspberry Pi 2 (armhf, Cortex-A7) on Debian 12:
# Debian's cross compiler (crossbuild-essential-armhf) with its own C and C++
# libraries, and the armhf Fast DDS, yaml-cpp, ... from a sysroot of unpacked
# Debian packages (scripts/cross_build_armhf.sh makes it). Tests run under
# qemu-arm-static with the sysroot's libraries.
#   cmake -S . -B build-armhf -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-armhf.cmake -DPIXYSLAM_ARMHF_SYSROOT=DIR
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR armv7l)
set(CMAKE_C_COMPILER arm-linux-gnueabihf-gcc)
set(CMAKE_CXX_COMPILER arm-linux-gnueabihf-g++)

set(PIXYSLAM_ARMHF_SYSROOT "$ENV{PIXYSLAM_ARMHF_SYSROOT}" CACHE PATH "Unpacked armhf Debian packages")
if(NOT IS_DIRECTORY "${PIXYSLAM_ARMHF_SYSROOT}/usr/lib/arm-linux-gnueabihf")
  message(FATAL_ERROR "PIXYSLAM_ARMHF_SYSROOT='${PIXYSLAM_ARMHF_SYSROOT}' is not an armhf sysroot "
                      "(make one with scripts/cross_build_armhf.sh)")
endif()
set(CMAKE_FIND_ROOT_PATH "${PIXYSLAM_ARMHF_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)  # fastddsgen, java: the host's
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# -Wno-psabi: GCC notes an ABI change of GCC 7.1 on every std::vector<Eigen> call.
set(cpu_flags "-mcpu=cortex-a7 -mfpu=neon-vfpv4 -mfloat-abi=hard -Wno-psabi")
# Debian's multiarch headers (fastrtps/config.h, openssl/opensslconf.h) of the sysroot.
string(APPEND cpu_flags " -isystem ${PIXYSLAM_ARMHF_SYSROOT}/usr/include/arm-linux-gnueabihf")
set(CMAKE_C_FLAGS_INIT "${cpu_flags}")
set(CMAKE_CXX_FLAGS_INIT "${cpu_flags}")
set(lib_dirs "${PIXYSLAM_ARMHF_SYSROOT}/usr/lib/arm-linux-gnueabihf;${PIXYSLAM_ARMHF_SYSROOT}/lib/arm-linux-gnueabihf")
foreach(dir IN LISTS lib_dirs)
  string(APPEND CMAKE_EXE_LINKER_FLAGS_INIT " -Wl,-rpath-link,${dir}")
  string(APPEND CMAKE_SHARED_LINKER_FLAGS_INIT " -Wl,-rpath-link,${dir}")
endforeach()

# ctest and gtest_discover_tests run armhf programs through the emulator.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-arm-static -L ${PIXYSLAM_ARMHF_SYSROOT})
