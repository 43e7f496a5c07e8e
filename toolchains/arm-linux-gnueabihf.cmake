# 32-bit ARM Linux, hard float (Debian armhf): Cortex-A7 class boards with NEON
# and VFPv4 (Raspberry Pi 2, Allwinner H3/A20, i.MX7), gcc-arm-linux-gnueabihf.
# Cortex-A9 (i.MX6, Zynq-7000) has NEON but only VFPv3, no fused multiply-add:
# build for it with -DRC_CROSS_C_FLAGS="-march=armv7-a -mfpu=neon -mfloat-abi=hard"
# -DRC_CROSS_QEMU_CPU=cortex-a9. (With -std=c99 gcc contracts no a*b+c into an
# FMA, so only explicit fma() calls would differ.)
set(CMAKE_SYSTEM_PROCESSOR armv7l)
set(RC_CROSS_TRIPLE arm-linux-gnueabihf)
set(RC_CROSS_QEMU qemu-arm)
if(NOT DEFINED RC_CROSS_QEMU_CPU)
  set(RC_CROSS_QEMU_CPU cortex-a7)
endif()
if(NOT DEFINED RC_CROSS_C_FLAGS)
  set(RC_CROSS_C_FLAGS "-march=armv7-a -mfpu=neon-vfpv4 -mfloat-abi=hard")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
