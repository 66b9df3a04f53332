# orogen — the two commands a newcomer needs:
#   make demo   installs missing Debian packages, builds (Release), runs pipelines/default.orogen into out/
#   make test   the same set-up and build, then every test with ctest
BUILD ?= build
JOBS  ?= 2

.PHONY: all setup configure build demo test bench clean

all: build

setup:
	@tools/setup.sh

configure: setup
	@cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null

build: configure
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	$(BUILD)/bin/orogen run pipelines/default.orogen --out out

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

# Benchmarks (Google Benchmark): figures go to docs/benchmarks.md.
bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b --benchmark_min_time=0.2; done

clean:
	rm -rf $(BUILD) out
