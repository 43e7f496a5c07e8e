# Coverage-guided fuzzing (tests/fuzz) of what reads untrusted bytes (baked
# maps, PLY, Ouster metadata) and of the built-in backend's exactness against
# testing every triangle (trace). Included by the Makefile.
#
#   make fuzz   builds the fuzz targets with clang's libFuzzer, ASan and UBSan
#               (in $(BUILD)-fuzz: built-in backend only) and runs each for
#               FUZZ_SECONDS (default 60) from the checked-in corpus
#               (tests/fuzz/corpus/<name>). What it learns grows
#               $(BUILD)-fuzz/corpus/<name>; a finding is written to
#               $(BUILD)-fuzz/findings/ and stops the run with an error. Copy a
#               finding into tests/fuzz/corpus/<name> once it is fixed: every
#               build replays that corpus as the test fuzz_<name>_replay.
#
# trace's inputs grow to 5200 bytes (256 triangles, 64 rays with their own
# origins, four instances, a grid sensor, then a dynamic map's new vertices
# and placements): libFuzzer would otherwise cap them at the corpus' largest
# seed.
# Installs clang, its libFuzzer runtime and libcjson-dev (tools/setup-deps.sh
# fuzz), or prints the apt-get line when not root.
# Variables: FUZZ_SECONDS, FUZZ_TARGETS (default: baked ply ouster trace tum).

FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?= baked ply ouster trace tum
FUZZ_BUILD := $(BUILD)-fuzz

.PHONY: fuzz
fuzz:
	@sh tools/setup-deps.sh fuzz
	CC=clang $(CMAKE) -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRANGECAST_FUZZ=ON \
		-DRANGECAST_BUILD_TESTS=OFF -DRANGECAST_BUILD_SHARED=OFF -DRANGECAST_WITH_EMBREE=OFF \
		-DRANGECAST_WITH_VULKAN=OFF -DRANGECAST_SANITIZE=address,undefined \
		-DCMAKE_C_FLAGS=-fsanitize=fuzzer-no-link $(CMAKE_FLAGS)
	$(CMAKE) --build $(FUZZ_BUILD) -j $(JOBS)
	@mkdir -p $(FUZZ_BUILD)/findings
	@for t in $(FUZZ_TARGETS); do \
		exe=$(FUZZ_BUILD)/tests/fuzz/fuzz_$$t; \
		if [ ! -x $$exe ]; then echo "fuzz: no fuzz_$$t in this build (fuzz_ouster needs libcjson-dev)"; continue; fi; \
		mkdir -p $(FUZZ_BUILD)/corpus/$$t; \
		echo "fuzz: $$t for $(FUZZ_SECONDS) s"; \
		max_len=; [ $$t = trace ] && max_len=-max_len=5200; \
		UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 $$exe -max_total_time=$(FUZZ_SECONDS) -timeout=10 $$max_len \
			-rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix=$(FUZZ_BUILD)/findings/$$t- \
			$(FUZZ_BUILD)/corpus/$$t tests/fuzz/corpus/$$t 2>$(FUZZ_BUILD)/fuzz_$$t.log || \
			{ tail -n 40 $(FUZZ_BUILD)/fuzz_$$t.log; echo "fuzz: $$t found something: $(FUZZ_BUILD)/findings/"; exit 1; }; \
		grep -E "stat::number_of_executed_units|stat::new_units_added" $(FUZZ_BUILD)/fuzz_$$t.log | sed "s/^/fuzz: $$t /"; \
	done
