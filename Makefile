# Front door to the CMake build. `make demo` and `make test` install what they
# need (tools/setup-deps.sh) on Debian 12, then build and run.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
CMAKE := cmake
SAN_BUILD := $(BUILD)-asan

.PHONY: all build deps-demo deps-test demo test test-fast asan ubsan sanitize tsan test-clang valgrind install bench clean help

all: build

help:
	@echo "make            build the library, the rangecast program and the tests"
	@echo "make demo       install deps, build, simulate a VLP-16 and a D435 in the demo map (writes out/)"
	@echo "make test       install deps, build, run all tests, then again under ASan+UBSan"
	@echo "make test-fast  run the tests once (no sanitizer pass)"
	@echo "make asan       tests under AddressSanitizer + UndefinedBehaviorSanitizer"
	@echo "make valgrind   tests under valgrind memcheck (leaks are errors)"
	@echo "make tsan       tests under ThreadSanitizer (built-in backend; a data race fails the test)"
	@echo "make test-clang the library, tools and tests built with clang (-Werror), the suite run once"
	@echo "make bench      rangecast bench on the standard workload (1M-triangle sphere)"
	@echo "make install    install into PREFIX (default /usr/local)"
	@echo "make cross-aarch64 | cross-armhf | cross-riscv64   cross-build and run the suite under qemu-user"
	@echo "make test-nothreads   the suite with RANGECAST_WITH_THREADS=OFF"
	@echo "make static-size      static core library size per target (-Os)"
	@echo "make fuzz            fuzz the file readers and the traversal (clang libFuzzer; FUZZ_SECONDS each)"

deps-demo:
	@sh tools/setup-deps.sh demo
deps-test:
	@sh tools/setup-deps.sh test

$(BUILD)/CMakeCache.txt:
	$(CMAKE) -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

build: $(BUILD)/CMakeCache.txt
	$(CMAKE) --build $(BUILD) -j $(JOBS)

demo: deps-demo
	$(CMAKE) -S . -B $(BUILD)-demo -DCMAKE_BUILD_TYPE=Release -DRANGECAST_BUILD_TESTS=OFF $(CMAKE_FLAGS)
	$(CMAKE) --build $(BUILD)-demo -j $(JOBS) --target rangecast
	./$(BUILD)-demo/tools/rangecast demo --out out

test-fast: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# (configured again: deps-test may have just unpacked the ray query tests' driver)
test: deps-test
	$(CMAKE) -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS) >/dev/null
	$(MAKE) test-fast
	$(MAKE) asan

asan sanitize:
	$(CMAKE) -S . -B $(SAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DRANGECAST_SANITIZE=address,undefined \
		-DRANGECAST_BUILD_SHARED=OFF $(CMAKE_FLAGS)
	$(CMAKE) --build $(SAN_BUILD) -j $(JOBS)
	cd $(SAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
		RC_TEST_QUICK=1 ctest --output-on-failure -j $(JOBS)

ubsan: asan

# The suite under ThreadSanitizer: the thread pool, the parallel build and
# contexts used from several threads. A reported race makes the program exit
# non-zero, so its test fails. Built-in backend only: Embree's TBB and
# lavapipe's threads synchronise in ways TSan cannot see without their own
# instrumented builds.
TSAN_BUILD := $(BUILD)-tsan
tsan: deps-test
	$(CMAKE) -S . -B $(TSAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DRANGECAST_SANITIZE=thread \
		-DRANGECAST_BUILD_SHARED=OFF -DRANGECAST_WITH_EMBREE=OFF -DRANGECAST_WITH_VULKAN=OFF $(CMAKE_FLAGS)
	$(CMAKE) --build $(TSAN_BUILD) -j $(JOBS)
	cd $(TSAN_BUILD) && TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 RC_TEST_QUICK=1 \
		ctest --output-on-failure -j $(JOBS)

# The whole build with clang and the suite run once (quick sizes): issue 2
# asks for -Werror builds clean with gcc and clang, and they warn apart:
# clang's -Wcast-align, for one, warns on x86-64, where gcc's stays quiet.
CLANG_BUILD := $(BUILD)-clang
test-clang: deps-test
	@command -v clang >/dev/null || { echo "test-clang: apt-get install -y clang"; exit 1; }
	CC=clang $(CMAKE) -S . -B $(CLANG_BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)
	$(CMAKE) --build $(CLANG_BUILD) -j $(JOBS)
	cd $(CLANG_BUILD) && RC_TEST_QUICK=1 ctest --output-on-failure -j $(JOBS)

# Every cmocka runner under valgrind (quick sizes; the Vulkan backend is left
# out, runners and shared suites alike: lavapipe's and LLVM's own memory and
# glibc's dlopen of the driver are not ours to judge), then every fuzz
# target's replay over its checked-in corpus. ctest -T memcheck would need
# CTest's dashboard files, so the programs are called directly: the test_*
# and fuzz_*_replay executables ctest lists for this build (a runner whose test
# was removed stays in $(BUILD)/tests and is not run), scripts left out.
# VALGRIND_TESTS (a ctest -R regex) picks some, e.g. VALGRIND_TESTS=test_arena.
VALGRIND_TESTS ?= .
valgrind: build
	@command -v valgrind >/dev/null || { echo "valgrind: apt-get install -y valgrind"; exit 1; }
	cd $(BUILD) && tests=$$(ctest -N -R '$(VALGRIND_TESTS)' | sed -n 's/^ *Test *#[0-9]*: \(test_[A-Za-z0-9_]*\|fuzz_[a-z]*_replay\)$$/\1/p') && \
	[ -n "$$tests" ] || { echo "valgrind: ctest lists no test_* runner or fuzz replay in $(BUILD)"; exit 1; }; \
	for t in $$tests; do \
		case $$t in *vulkan*) continue ;; esac; \
		exe=./tests/$$t; args=; \
		case $$t in fuzz_*_replay) name=$${t#fuzz_}; exe=./tests/fuzz/$$t; args=$(CURDIR)/tests/fuzz/corpus/$${name%_replay} ;; esac; \
		[ -f $$exe ] && [ -x $$exe ] && [ "$$(head -c 4 $$exe)" = "$$(printf '\177ELF')" ] || continue; \
		echo "valgrind $$t"; \
		RC_TEST_QUICK=1 RC_TEST_SKIP_BACKENDS=vulkan valgrind -q --leak-check=full --errors-for-leak-kinds=definite,indirect \
			--suppressions=$(CURDIR)/tests/valgrind.supp \
			--error-exitcode=1 $$exe $$args >/dev/null || { echo "valgrind: $$t failed"; exit 1; }; \
	done; echo "valgrind: no errors, no leaks"

bench: build
	./$(BUILD)/tools/rangecast bench --sensor vlp16 --backend bvh --threads 2 --repeat 3

PREFIX ?= /usr/local
install: build
	$(CMAKE) --install $(BUILD) --prefix $(PREFIX)

clean:
	rm -rf $(BUILD) $(BUILD)-demo $(SAN_BUILD) $(TSAN_BUILD) $(CLANG_BUILD) out

-include mk/*.mk
