# 64-bit ARM Linux: Cortex-A53/A72/A76 class boards (Jetson, Raspberry Pi 4/5,
# RK3588) with Debian's gcc-aarch64-linux-gnu. Generic ARMv8-A code runs on all
# of them; tune for one with -DRC_CROSS_C_FLAGS=-mcpu=cortex-a76 (RPi 5, RK3588)
# or -mcpu=cortex-a72 (RPi 4), and -DRC_CROSS_QEMU_CPU=cortex-a76 to match.
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(RC_CROSS_TRIPLE aarch64-linux-gnu)
set(RC_CROSS_QEMU qemu-aarch64)
if(NOT DEFINED RC_CROSS_QEMU_CPU)
  set(RC_CROSS_QEMU_CPU cortex-a53)
endif()
if(NOT DEFINED RC_CROSS_C_FLAGS)
  set(RC_CROSS_C_FLAGS "-march=armv8-a")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
