# orogen — the two commands a newcomer needs:
#   make demo   installs missing Debian packages, builds (Release), runs pipelines/default.orogen into out/
#   make test   the same set-up and build, then every test with ctest
BUILD ?= build
JOBS  ?= 2

.PHONY: all setup setup-tests configure build demo test bench bench-check tidy paraview clean asan asan-ci asan-configure tsan fuzz-smoke fuzz-long

all: build

setup:
	@tools/setup.sh

setup-tests:
	@tools/setup.sh --tests

# CMAKE_ARGS: more cmake options (CI: -DOROGEN_BUILD_BENCHMARKS=OFF, as it runs no benchmark).
CMAKE_ARGS ?=
configure: setup
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) >/dev/null

build: configure
	cmake --build $(BUILD) -j$(JOBS)

# The command and its plugins only (target orogen_demo), not the tests. A first build says how long it will
# take: SECONDS_PER_STEP is a compile step's average on one core of the 2-core machine of docs/benchmarks.md.
SECONDS_PER_STEP ?= 5
demo: configure
	@if [ ! -x $(BUILD)/bin/orogen ]; then \
	  steps=$$(ninja -C $(BUILD) -t commands orogen_demo | wc -l); \
	  echo "make demo: a first build of orogen and its plugins: $$steps steps, about $$(( (steps * $(SECONDS_PER_STEP) / $(JOBS) + 59) / 60 )) min on $(JOBS) cores (later runs rebuild only what changed)"; \
	fi
	@start=$$(date +%s); cmake --build $(BUILD) -j$(JOBS) --target orogen_demo && \
	  echo "make demo: built in $$(( $$(date +%s) - start )) s; running pipelines/default.orogen into out/"
	$(BUILD)/bin/orogen run pipelines/default.orogen --out out
	@echo "make demo: open it with build/bin/orogen-view out/ (make build first), or in ParaView:" \
	  "tools/pvbatch out/paraview/orogen.py --screenshot view.png"

test: setup-tests build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

# Benchmarks (Google Benchmark): figures go to docs/benchmarks.md.
bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b --benchmark_min_time=0.2; done

# A function of at most 150 lines and 8 parameters, over kernel, libs, plugins, viewer and python (clang-tidy-14's
# readability-function-size, .clang-tidy): a CI phase, so the limit stays a rule.
tidy: configure
	tools/tidy.sh $(BUILD)

# ParaView 5.11 for tools/pvbatch (Debian's .debs unpacked into build/paraview; tools/paraview.sh).
paraview:
	tools/paraview.sh $(BUILD)/paraview

# The speed ratios a change must not lose (export against cp, the landscape step against fastscapelib, a
# 1080p frame, the SPH step, the default pipeline), in about three minutes, against the figures recorded in
# docs/benchmarks.md ("Ratio checks"). Run it before a change to one of those paths lands.
BENCH_CHECK_TARGETS = orogen_demo bench_diamond_square bench_export_gltf bench_stream_power bench_render bench_sph
bench-check: configure
	cmake --build $(BUILD) -j$(JOBS) --target $(BENCH_CHECK_TARGETS)
	python3 tools/bench_check.py $(BUILD)

# Sanitizer builds (clang-14, tools/setup.sh installs it); see docs/hardening.md.
#   make asan        AddressSanitizer + UndefinedBehaviorSanitizer build of the whole tree (-O1) and every
#                    test in it (the shipped pipelines included), with the libFuzzer targets
#   make tsan        ThreadSanitizer build of the parallel cores and the exporters, and their tests
#   make fuzz-smoke  FUZZ_SECONDS (default 20) of each fuzz target from FUZZ_SEED (default 1), so a failure in CI
#                    replays here with the same seed; the crashing input is printed in hex (needs `make asan`'s build)
#   make fuzz-long   FUZZ_RUNS (default 1000000) executions of each target, one job each
SAN_FLAGS   = -O1 -gline-tables-only -fno-omit-frame-pointer -fsanitize-ignorelist=$(CURDIR)/tools/sanitizer-ignorelist.txt
ASAN_BUILD ?= build-asan
TSAN_BUILD ?= build-tsan
# The thread-parallel cores (every erode, generate, tectonics and import plugin, the exporters) and their tests,
# the cache's parallel copies and hashes, and the kernel tests that run specs on several threads. Not here: the
# render passes, export:video and export:paraview (their threads are llvmpipe's, FFmpeg's and ParaView's, not
# instrumented) — CI's ASan phase covers their code (ASAN_CI).
TSAN_ONLY  ?= ^/plugins/(erode|generate|tectonics|import|process)/[^/]+$$|^/plugins/export/(png|raw|gltf|vdb|vtk|geotiff|exr|maps|tiles)$$|^/tests/plugins/(erode|generate|tectonics)/[^/]+$$|^/tests/plugins/export/(png|raw|gltf|vdb|geotiff|exr|maps|tiles)$$|^/tests/(cache|kernel)$$|^/tests/libs/(analysis|climate|formats|mesh|relief|solvers)$$
# Tests TSan gains nothing from, left to the other phases (they were half of the TSan phase's test time):
# check-time diagnostics, which run no thread (the kernel's run under ASan+UBSan in asan-ci, the plugins'
# in the release suite), and the long physics validations (dam break, hydrostatics, experiment 4.1, the
# talus piles, the river-network and realism statistics) whose parallel loops each core's shorter
# "same bytes on one and two threads" test runs under TSan too. Also left out: the golden-output
# comparisons (the release and ASan phases check every golden; TSan's share of the same loops is in the
# thread tests), the cache's bookkeeping (eviction, staleness, damaged entries: one process, one thread; its
# parallel copies and hashes stay, in CacheRun.ColdAndWarm... and test_cache), the kill/rollback tests
# (processes, not threads), GDAL reading orogen's files back (GDAL is not instrumented), and the
# analysis library's agreement with terrain_stats.py on the reference DEMs (one thread's arithmetic; its
# FFT's threads are in Figures.TheSameBitsWithOneThreadOrTwo).
TSAN_SKIP  ?= ^Specs/BadSpec\.|^Confinement\.|^Cli\.|^Inputs\.|^CacheCommand\.|^Runner\.ExitCodes|^Outputs\.BadPng|Cli\.Bad|CliBadInput|Cli\.TooMany|Node\.BadInput|^Series\.ATimelapseThatWouldNotFit|^SphDamBreak(3D)?\.|^SphHydrostatics(3D)?\.|^Experiment41\.|TallColumnBecomesPileAtTalusSlope|RainOnRoughTerrainGivesANetworkNotSpeckle|ShippedPipelinesKeepTheirGoldenOutputs|^CacheRun\.(Eviction|AnImporter|Series|TheDefaultFolder|Damaged|ANewSeed|AnEntry|WhatACached|ARebuilt|ADownstream|AFolder)|^AllOrNothing\.|GdalReadsTheMosaic|GdalinfoReadsIt|^Outputs\.(A16BitPng|AddingANode)|^Pipe\.(ConservesWaterAndMaterialOver10000Steps|AnyTimeStepStaysFinite)|^SphDitches\.|^SphNode\.BadInput|^PlatesCli\.Bad|^TilesCli\.BadParameters|^Reference\.
# What `make asan` configures: empty = the whole tree. CI (.ci/run) runs ASAN_CI: every plugin, the kernel,
# the fuzz targets and the cache with their tests, the render passes' tests, and the shipped pipelines end to
# end at their test sizes (tests/pipelines: every pipeline on 1 and 2 threads against its golden hashes, so
# every plugin's code runs under ASan+UBSan through a real spec), and libs/ with its tests. The plugins' own unit tests run under
# TSan+UBSan (TSAN_ONLY). Both sanitizers over every test would not fit CI's 30 minutes on 2 cores
# (docs/hardening.md).
ASAN_ONLY  ?=
ASAN_CI     = ^/tests/(kernel|fuzz|cache|pipelines)|^/tests/plugins/(render|analyze)/terrain$$|^/tests/libs/[^/]+$$|^/plugins/[^/]+/[^/]+$$
FUZZ_SECONDS ?= 20
FUZZ_SEED    ?= 1
FUZZ_RUNS    ?= 1000000
FUZZ_TARGETS  = spec overrides png sidecar cache exr f32
# The sanitizer builds link with lld when it is installed (lld-14: a sanitizer link is 2-3x faster than
# with bfd, ~70 links a build).
SAN_LD      := $(if $(shell command -v ld.lld 2>/dev/null),-fuse-ld=lld,)
# Extra cmake arguments for the sanitizer builds, e.g. SAN_CMAKE=-DCMAKE_CXX_COMPILER_LAUNCHER=ccache
SAN_CMAKE    ?=
ASAN_CTEST   ?=
# intercept_tls_get_addr=0: up to LLVM 16 the runtime's __tls_get_addr interceptor takes a dynamic TLS block
# whose start is 16 bytes past a page boundary for a pre-2.25 glibc header and reads two words before it;
# at exit LeakSanitizer's tracer then dies ("Tracer caught signal 11") with no leak found. Which block
# lands there is chance, so it reads as a flake (CI, stop 21: the default pipeline, OSMesa's and the
# plugins' TLS loaded). Without the interceptor the dynamic TLS blocks are still scanned as heap.
export ASAN_OPTIONS  ?= detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:intercept_tls_get_addr=0
export UBSAN_OPTIONS ?= print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS  ?= suppressions=$(CURDIR)/tools/lsan.supp
export TSAN_OPTIONS  ?= halt_on_error=1:second_deadlock_stack=1:suppressions=$(CURDIR)/tools/tsan.supp

# CI's sanitizer phase: ASan + UBSan over the kernel, the fuzz corpora and the plugins its tests use.
asan-ci: ASAN_ONLY = $(ASAN_CI)
# out_of_tree_plugin and out_of_tree_process configure and build a plugin outside the tree (34 s under ASan): its code is one
# node the release phase loads; what it tests is the install, not memory.
asan-ci: ASAN_CTEST = -E '^out_of_tree_(plugin|process)$$'
asan-ci: asan

asan: asan-configure
	cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && ctest --output-on-failure --no-tests=error -j$(JOBS) $(ASAN_CTEST)

asan-configure: setup
	@cmake -S . -B $(ASAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
	  -DCMAKE_CXX_FLAGS_SANITIZE="$(SAN_FLAGS) -fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=all" \
	  -DCMAKE_C_FLAGS_SANITIZE="$(SAN_FLAGS) -fsanitize=address,undefined -fno-sanitize-recover=all" \
	  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined $(SAN_LD)" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined $(SAN_LD)" \
	  -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined $(SAN_LD)" \
	  -DOROGEN_BUILD_BENCHMARKS=OFF -DOROGEN_BUILD_VIEWER=OFF -DOROGEN_BUILD_FIGURES=OFF -DOROGEN_FUZZ=ON '-DOROGEN_ONLY=$(ASAN_ONLY)' $(SAN_CMAKE) >/dev/null

tsan: setup
	@cmake -S . -B $(TSAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
	  -DCMAKE_CXX_FLAGS_SANITIZE="$(SAN_FLAGS) -fsanitize=thread,undefined -fno-sanitize=vptr -fno-sanitize-recover=all" \
	  -DCMAKE_C_FLAGS_SANITIZE="$(SAN_FLAGS) -fsanitize=thread,undefined -fno-sanitize-recover=all" \
	  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread,undefined $(SAN_LD)" -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=thread,undefined $(SAN_LD)" \
	  -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=thread,undefined $(SAN_LD)" \
	  -DOROGEN_BUILD_BENCHMARKS=OFF -DOROGEN_BUILD_VIEWER=OFF -DOROGEN_BUILD_FIGURES=OFF '-DOROGEN_ONLY=$(TSAN_ONLY)' $(SAN_CMAKE) >/dev/null
	cmake --build $(TSAN_BUILD) -j$(JOBS)
	cd $(TSAN_BUILD) && ctest --output-on-failure --no-tests=error -j$(JOBS) -LE 'pipelines|fuzz' -E '^out_of_tree_(plugin|process)$$|$(TSAN_SKIP)'

fuzz-smoke:
	@cd $(ASAN_BUILD)/tests && for t in $(FUZZ_TARGETS); do \
	  mkdir -p fuzz-corpus/$$t && \
	  ./fuzz_$$t -seed=$(FUZZ_SEED) -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 -artifact_prefix=fuzz-$$t- \
	    fuzz-corpus/$$t $(CURDIR)/tests/fuzz/corpus/$$t 2>fuzz-$$t.log || { \
	    grep -m5 -E 'ERROR|runtime error|SUMMARY' fuzz-$$t.log; tail -30 fuzz-$$t.log; \
	    for c in fuzz-$$t-crash-* fuzz-$$t-leak-* fuzz-$$t-timeout-* fuzz-$$t-oom-*; do \
	      [ -f "$$c" ] && { echo "fuzz_$$t: the input that failed ($$c), in hex:"; od -An -tx1 -v "$$c" | head -64; }; done; \
	    exit 1; }; \
	  echo "fuzz_$$t: $$(grep -h 'stat::number_of_executed_units' fuzz-$$t.log | awk '{print $$2}') executions in $(FUZZ_SECONDS) s, no crash"; \
	done

fuzz-long:
	@cd $(ASAN_BUILD)/tests && for t in $(FUZZ_TARGETS); do \
	  mkdir -p fuzz-corpus/$$t && \
	  /usr/bin/time -f "fuzz_$$t: %e s wall" ./fuzz_$$t -runs=$(FUZZ_RUNS) -print_final_stats=1 fuzz-corpus/$$t \
	    $(CURDIR)/tests/fuzz/corpus/$$t 2>fuzz-long-$$t.log || { tail -50 fuzz-long-$$t.log; exit 1; }; \
	done

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(TSAN_BUILD) out
