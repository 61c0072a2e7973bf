# sandbench: the two README commands (`make reproduce`, `make test`) and helpers.
# Every target that builds first runs `deps`, which installs missing Debian packages.

PRESET ?= release
BUILD_DIR := build/$(PRESET)
PYTHON := /usr/bin/python3
JOBS ?= 2
BENCH_FILTER ?= .
FULL ?= 0

FUZZ_SECONDS ?= 60

.PHONY: all deps configure build test test-asan reproduce bench goldens fuzz format format-check lint clean

all: build

deps:
	@bash .ci/deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j$(JOBS)

test: build
	@ctest --test-dir $(BUILD_DIR) --output-on-failure -j$(JOBS) --timeout 900

# The same suite under AddressSanitizer and UndefinedBehaviorSanitizer. LeakSanitizer ignores
# only the leaks of third-party libraries listed in tests/lsan.supp (the GL stack); the
# variables reach every process the tests start (the reproduction's `interactive` runs too).
test-asan:
	@LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
		UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
		$(MAKE) --no-print-directory test PRESET=asan-ubsan

# ENGINE=local (a pool of JOBS runs on this machine) or ENGINE=slurm (one job array through
# sbatch; SLURM_PARTITION, SLURM_ACCOUNT, SLURM_TIME and SLURM_MEM per array task, at most
# SLURM_PARALLEL tasks at once, SLURM_BATCH runs per task, SLURM_ARGS passed to sbatch as is).
ENGINE ?= local
SLURM_PARALLEL ?= 32
SLURM_BATCH ?= 1
reproduce: build
	@$(PYTHON) experiments/reproduce.py --sandbench $(BUILD_DIR)/harness/sandbench --results results \
		$(if $(filter 1,$(FULL)),--full,) --engine $(ENGINE) --jobs $(JOBS) \
		$(if $(SLURM_PARTITION),--partition $(SLURM_PARTITION),) $(if $(SLURM_ACCOUNT),--account $(SLURM_ACCOUNT),) \
		$(if $(SLURM_TIME),--time $(SLURM_TIME),) $(if $(SLURM_MEM),--mem $(SLURM_MEM),) \
		--parallel $(SLURM_PARALLEL) --batch $(SLURM_BATCH) $(foreach a,$(SLURM_ARGS),--sbatch-arg=$(a))

bench: build
	@for b in $(BUILD_DIR)/tests/*_bench; do \
		echo "== $$b"; $$b --benchmark_filter='$(BENCH_FILTER)' --benchmark_repetitions=5 \
			--benchmark_report_aggregates_only=true || exit 1; \
	done

# Rewrites tests/regression/golden/*.json from the current code: review the diff.
goldens: build
	@SB_UPDATE_GOLDENS=1 $(BUILD_DIR)/tests/sb_regression_tests
	@git --no-pager diff --stat -- tests/regression/golden || true

# libFuzzer targets (clang, AddressSanitizer) for FUZZ_SECONDS each. Corpora are kept in
# build/fuzz/corpus-*, seeded from the shipped scenes and sessions; a crash leaves its input in
# build/fuzz/. The test suite runs each target briefly with a fixed seed (label `fuzz`).
FUZZ_TARGETS := scene_fuzz replay_fuzz run_file_fuzz stamp_fuzz
fuzz:
	@bash .ci/deps.sh fuzz
	@CC=clang CXX=clang++ cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSANDBENCH_BUILD_FUZZ=ON \
		-DSANDBENCH_BUILD_TESTS=OFF -DSANDBENCH_BUILD_BENCH=OFF \
		-DCMAKE_CXX_FLAGS="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer" >/dev/null
	@cmake --build build/fuzz -j$(JOBS) --target $(FUZZ_TARGETS)
	@mkdir -p build/fuzz/corpus-scene_fuzz build/fuzz/corpus-replay_fuzz build/fuzz/corpus-run_file_fuzz \
		build/fuzz/corpus-stamp_fuzz
	@cp -n experiments/scenes/*.toml build/fuzz/corpus-scene_fuzz/
	@cp -n tests/fuzz/corpus/replay/*.csv build/fuzz/corpus-replay_fuzz/
	@for t in $(FUZZ_TARGETS); do \
		(cd build/fuzz && ./tests/fuzz/$$t -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1 corpus-$$t) || exit 1; \
	done

# Formatting (.clang-format) and static checks (.clang-tidy) on the C++ sources git tracks.
# format-check fails on any difference (CI runs it); `make format` rewrites the files.
# lint adds clang-tidy over the compile database (slow: CGAL headers; run it locally).
CXX_SOURCES = $(shell git ls-files '*.cpp' '*.hpp' '*.h')
TIDY_SCOPE := '^$(CURDIR)/(common|grid|tin|harness)/'

format-check:
	@bash .ci/deps.sh
	@clang-format --dry-run -Werror $(CXX_SOURCES) && echo "format-check: $(words $(CXX_SOURCES)) files formatted"

format:
	@bash .ci/deps.sh
	@clang-format -i $(CXX_SOURCES)

lint: format-check configure
	@bash .ci/deps.sh lint
	@run-clang-tidy -quiet -j$(JOBS) -p $(BUILD_DIR) $(TIDY_SCOPE)

clean:
	@rm -rf build
