# Cross builds for ARM boards (and RISC-V) with the tests under qemu-user, and
# the build-option checks that go with them. Included by the Makefile.
#
#   make cross-aarch64   64-bit ARM, Cortex-A53/A72/A76 (Jetson, RPi 4/5, RK3588)
#   make cross-armhf     32-bit ARMv7-A, NEON + VFPv4, hard float (Cortex-A7)
#   make cross-riscv64   RV64GC (best effort)
#   make cross           all three
#   make test-nothreads  host build with RANGECAST_WITH_THREADS=OFF, whole suite
#   make static-size     -Os static core per target, threads on/off: a table
#   make cross-clean     remove the folders above
#   make abi-golden      rewrite tests/abi/lp64.txt and ilp32.txt after an
#                        intended change of a public struct (appended field)
#
# A cross-<target> installs what it needs (tools/setup-deps.sh: as root, or it
# prints the apt-get line and stops), configures $(BUILD)-<target> with
# toolchains/<triple>.cmake, builds the library and the tests, and runs the
# whole cmocka suite under qemu-user (CMAKE_CROSSCOMPILING_EMULATOR, no binfmt)
# with RC_TEST_QUICK=1, as qemu is ~15x slower than native. The tools are off
# (desktop libraries), Embree too (no armhf package; its arm64 build spins
# forever in rtcIntersect1 under qemu-user).
#
# cmocka for the target: aarch64 uses Debian's multiarch libcmocka-dev:arm64;
# armhf and riscv64 build it from bookworm's source package into
# $(BUILD)-<target>/_deps/cmocka, once (toolchains/cmocka-from-source.sh): the
# armhf multiarch index has broken `apt-get update` on these machines, and
# bookworm has no riscv64.
#
# Variables:
#   CROSS_CMAKE_FLAGS   more CMake options for the cross builds
#   CROSS_CTEST_FLAGS   more ctest options (e.g. -R scenes, -E mesh_intersect)
#   CROSS_CMOCKA        aarch64 only: multiarch (default) or source
#   CROSS_VULKAN        aarch64 only: auto (default: ON when the arm64 Vulkan
#                       loader and glslangValidator are installed, which
#                       deps-cross-aarch64 does), ON or OFF. The backend then
#                       compiles and links for arm64; its tests skip under qemu,
#                       which has no Vulkan device.

CROSS_CMAKE_FLAGS ?=
CROSS_CTEST_FLAGS ?=
CROSS_CMOCKA ?= multiarch
CROSS_VULKAN ?= auto

CROSS_COMMON_FLAGS := -DCMAKE_BUILD_TYPE=Release -DRANGECAST_BUILD_TOOLS=OFF -DRANGECAST_WITH_EMBREE=OFF

.PHONY: cross cross-aarch64 cross-armhf cross-riscv64 \
	deps-cross-aarch64 deps-cross-armhf deps-cross-riscv64 \
	test-nothreads static-size abi-golden cross-clean

cross: cross-aarch64 cross-armhf cross-riscv64

# $(call rc_cross_cmocka_source,<target>,<triple>): cmocka into $(BUILD)-<target>/_deps/cmocka
rc_cross_cmocka_source = sh toolchains/cmocka-from-source.sh toolchains/$(2).cmake $(BUILD)-$(1)/_deps
rc_cross_cmocka_prefix = -DCMAKE_PREFIX_PATH=$(abspath $(BUILD)-$(1)/_deps/cmocka)

# $(call rc_cross_build,<target>,<triple>,<more cmake flags>)
define rc_cross_build
	$(CMAKE) -S . -B $(BUILD)-$(1) -DCMAKE_TOOLCHAIN_FILE=$(CURDIR)/toolchains/$(2).cmake \
		$(CROSS_COMMON_FLAGS) $(3) $(CROSS_CMAKE_FLAGS)
	$(CMAKE) --build $(BUILD)-$(1) -j $(JOBS)
	cd $(BUILD)-$(1) && RC_TEST_QUICK=1 ctest --output-on-failure -j $(JOBS) $(CROSS_CTEST_FLAGS)
endef

# --- aarch64 -----------------------------------------------------------------
deps-cross-aarch64:
	@sh tools/setup-deps.sh cross-aarch64
ifeq ($(CROSS_CMOCKA),source)
	@$(call rc_cross_cmocka_source,aarch64,aarch64-linux-gnu)
else
	@sh tools/setup-deps.sh multiarch-arm64
endif

# Expanded after deps-cross-aarch64 has run (prerequisites come first).
rc_cross_vulkan_aarch64 = $(if $(filter auto,$(CROSS_VULKAN)),$(shell \
	test -e /usr/lib/aarch64-linux-gnu/libvulkan.so && command -v glslangValidator >/dev/null \
	&& echo ON || echo OFF),$(CROSS_VULKAN))

cross-aarch64: deps-cross-aarch64
	$(call rc_cross_build,aarch64,aarch64-linux-gnu,-DRANGECAST_WITH_VULKAN=$(rc_cross_vulkan_aarch64) \
		$(if $(filter source,$(CROSS_CMOCKA)),$(call rc_cross_cmocka_prefix,aarch64)))

# --- armhf -------------------------------------------------------------------
deps-cross-armhf:
	@sh tools/setup-deps.sh cross-armhf
	@$(call rc_cross_cmocka_source,armhf,arm-linux-gnueabihf)

cross-armhf: deps-cross-armhf
	$(call rc_cross_build,armhf,arm-linux-gnueabihf,-DRANGECAST_WITH_VULKAN=OFF $(call rc_cross_cmocka_prefix,armhf))

# --- riscv64 -----------------------------------------------------------------
deps-cross-riscv64:
	@sh tools/setup-deps.sh cross-riscv64
	@$(call rc_cross_cmocka_source,riscv64,riscv64-linux-gnu)

cross-riscv64: deps-cross-riscv64
	$(call rc_cross_build,riscv64,riscv64-linux-gnu,-DRANGECAST_WITH_VULKAN=OFF $(call rc_cross_cmocka_prefix,riscv64))

# --- build-option checks -----------------------------------------------------
# The core without threads (src/core/threads.c runs every task inline), as on a
# bare single-core board; static library only, no optional backends.
test-nothreads: deps-test
	$(CMAKE) -S . -B $(BUILD)-static-nothreads -DCMAKE_BUILD_TYPE=Release -DRANGECAST_WITH_THREADS=OFF \
		-DRANGECAST_BUILD_SHARED=OFF -DRANGECAST_BUILD_TOOLS=OFF -DRANGECAST_WITH_EMBREE=OFF \
		-DRANGECAST_WITH_VULKAN=OFF $(CMAKE_FLAGS)
	$(CMAKE) --build $(BUILD)-static-nothreads -j $(JOBS)
	cd $(BUILD)-static-nothreads && ctest --output-on-failure -j $(JOBS)

static-size:
	@sh tools/setup-deps.sh cross
	@sh tools/static-size.sh

# abi_layout needs only the header: compile it for the host (LP64) and for
# armhf (ILP32, static, run by qemu-arm) and keep what they print.
abi-golden: deps-cross-armhf
	@mkdir -p $(BUILD)-static
	cc -std=c99 -Iinclude tests/abi_layout.c -o $(BUILD)-static/abi_layout_host
	arm-linux-gnueabihf-gcc -std=c99 -static -Iinclude tests/abi_layout.c -o $(BUILD)-static/abi_layout_armhf
	./$(BUILD)-static/abi_layout_host >tests/abi/lp64.txt
	qemu-arm ./$(BUILD)-static/abi_layout_armhf >tests/abi/ilp32.txt
	@git diff --stat -- tests/abi 2>/dev/null || true

cross-clean:
	rm -rf $(BUILD)-aarch64 $(BUILD)-armhf $(BUILD)-riscv64 $(BUILD)-static-nothreads build-static-size
