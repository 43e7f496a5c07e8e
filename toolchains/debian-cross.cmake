# Shared part of the Debian cross toolchain files in this folder; each of them
# sets RC_CROSS_TRIPLE, CMAKE_SYSTEM_PROCESSOR, RC_CROSS_QEMU (qemu-user's name
# for the architecture), RC_CROSS_QEMU_CPU and RC_CROSS_C_FLAGS, then includes
# this file.
#
# Compilers: Debian's cross gcc, /usr/bin/<triple>-gcc (gcc-<triple> packages).
# Libraries: the cross libc in /usr/<triple> (libc6-dev-<arch>-cross) and
# multiarch packages in /usr/lib/<triple> (dpkg --add-architecture <arch>;
# apt-get install libcmocka-dev:<arch>), or a prefix given in CMAKE_PREFIX_PATH
# (make cross-armhf builds cmocka into build-armhf/_deps/cmocka).
# Tests: ctest and try_run run target programs through
# CMAKE_CROSSCOMPILING_EMULATOR (qemu-user), so binfmt_misc is not needed.
#
#   cmake -S . -B build-aarch64 -DCMAKE_TOOLCHAIN_FILE=toolchains/aarch64-linux-gnu.cmake
#
# Cache variables to adjust for a particular board (give them at the first
# configure of a build folder: they seed CMAKE_C_FLAGS):
#   RC_CROSS_C_FLAGS   target flags added to every compile (e.g. -mcpu=cortex-a76)
#   RC_CROSS_QEMU_CPU  the CPU qemu emulates for tests ("" = qemu's default, "max")

set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_LIBRARY_ARCHITECTURE ${RC_CROSS_TRIPLE})

set(CMAKE_C_COMPILER ${RC_CROSS_TRIPLE}-gcc)
if(EXISTS /usr/bin/${RC_CROSS_TRIPLE}-g++)
  set(CMAKE_CXX_COMPILER ${RC_CROSS_TRIPLE}-g++)
endif()
# ar, ranlib, strip: CMake takes <triple>-ar ... from the compiler's prefix.

set(RC_CROSS_C_FLAGS "${RC_CROSS_C_FLAGS}" CACHE STRING "Target CPU flags for every compile")
set(CMAKE_C_FLAGS_INIT "${RC_CROSS_C_FLAGS}")
set(CMAKE_CXX_FLAGS_INIT "${RC_CROSS_C_FLAGS}")
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES RC_CROSS_C_FLAGS RC_CROSS_QEMU_CPU)

# Where find_* look. Programs (glslangValidator, ...) are the build machine's:
# NEVER. Libraries, headers and CMake packages: BOTH, because Debian's multiarch
# libraries live on the host root, in /usr/lib/<triple> and /usr/include, which
# ONLY would re-root to /usr/<triple>/usr/... and miss; CMAKE_LIBRARY_ARCHITECTURE
# steers the search to /usr/lib/<triple>, so the host's /usr/lib/x86_64-linux-gnu
# is never searched. /usr/<triple> holds the cross libc.
set(CMAKE_FIND_ROOT_PATH /usr/${RC_CROSS_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)

# pkg-config sees only the target's .pc files (as Debian's <triple>-pkg-config
# does). FindPkgConfig still adds CMAKE_PREFIX_PATH/lib/pkgconfig in front, which
# is how a cmocka built from source is found.
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/${RC_CROSS_TRIPLE}/pkgconfig:/usr/share/pkgconfig")

# qemu-user runs the tests. -L makes the target's dynamic loader come from the
# cross libc (libc6-<arch>-cross) in /usr/<triple>, and LD_LIBRARY_PATH makes
# libc.so.6 come from the same place: when multiarch libc6:<arch> is installed
# too (it is, with libcmocka-dev:<arch>), the loader's cache would otherwise
# hand the cross loader (2.36-8cross1) the multiarch libc (2.36-9+deb12uN), and
# that mixed glibc hangs in the first pthread_create. Other multiarch libraries
# (libcmocka.so.0) come from /usr/lib/<triple> through the loader's default
# path, a cmocka built from source through the tests' RPATH. -cpu pins the
# emulated core to the oldest one the flags target, so an instruction that core
# lacks fails the tests.
set(RC_CROSS_QEMU_CPU "${RC_CROSS_QEMU_CPU}" CACHE STRING "CPU qemu-user emulates for the tests (empty: qemu's default)")
find_program(RC_CROSS_QEMU_PATH NAMES ${RC_CROSS_QEMU} ${RC_CROSS_QEMU}-static)
if(RC_CROSS_QEMU_PATH)
  set(_rc_qemu ${RC_CROSS_QEMU_PATH})
else()
  set(_rc_qemu ${RC_CROSS_QEMU}) # not installed yet: ctest will say so
endif()
set(CMAKE_CROSSCOMPILING_EMULATOR ${_rc_qemu} -L /usr/${RC_CROSS_TRIPLE}
    -E LD_LIBRARY_PATH=/usr/${RC_CROSS_TRIPLE}/lib)
if(RC_CROSS_QEMU_CPU)
  list(APPEND CMAKE_CROSSCOMPILING_EMULATOR -cpu ${RC_CROSS_QEMU_CPU})
endif()
