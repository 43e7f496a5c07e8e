# 64-bit RISC-V Linux (RV64GC, lp64d: VisionFive 2, Milk-V, SpacemiT K1) with
# Debian's gcc-riscv64-linux-gnu. bookworm has no riscv64 multiarch packages
# (riscv64 became a release architecture in trixie): make cross-riscv64 builds
# cmocka from its Debian source package.
set(CMAKE_SYSTEM_PROCESSOR riscv64)
set(RC_CROSS_TRIPLE riscv64-linux-gnu)
set(RC_CROSS_QEMU qemu-riscv64)
if(NOT DEFINED RC_CROSS_QEMU_CPU)
  set(RC_CROSS_QEMU_CPU "")
endif()
if(NOT DEFINED RC_CROSS_C_FLAGS)
  set(RC_CROSS_C_FLAGS "-march=rv64gc -mabi=lp64d")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/debian-cross.cmake)
