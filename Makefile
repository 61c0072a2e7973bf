# sandbench: the two README commands (`make reproduce`, `make test`) and helpers.
# Every target that builds first runs `deps`, which installs missing Debian packages.

PRESET ?= release
BUILD_DIR := build/$(PRESET)
PYTHON := /usr/bin/python3
JOBS ?= 2
BENCH_FILTER ?= .
FULL ?= 0

FUZZ_SECONDS ?= 60

.PHONY: all deps configure build test test-asan test-tsan reproduce dem bench goldens fuzz format format-check lint clean

all: build

deps:
	@bash .ci/deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j$(JOBS)

# Skipped tests (GTEST_SKIP: no AVX-512 on this CPU, no xvfb-run, ...) are listed after the
# run with the reason each gave, so a CI log says what was not exercised.
test: build
	@status=0; ctest --test-dir $(BUILD_DIR) --output-on-failure -j$(JOBS) --timeout 900 \
	  $(if $(TEST_EXCLUDE),-E '$(TEST_EXCLUDE)',) || status=$$?; \
	  grep -h -A1 ': Skipped$$' $(BUILD_DIR)/Testing/Temporary/LastTest.log 2>/dev/null | \
	    grep -v -e '^--$$' -e ': Skipped$$' | sort | uniq -c | sed 's/^ */skipped: /'; exit $$status

# The same suite under AddressSanitizer and UndefinedBehaviorSanitizer. LeakSanitizer ignores
# only the leaks of third-party libraries listed in tests/lsan.supp (the GL stack); the
# variables reach every process the tests start (the reproduction's `interactive` runs too).
# slurm_sweep is left out (ASAN_ALL=1 keeps it): it runs reproduce_smoke's sandbench runs again
# through a local SLURM cluster, ten minutes under the sanitizers, which the CI stage cannot afford.
ASAN_ALL ?= 0
test-asan:
	@LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
		UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
		$(MAKE) --no-print-directory test PRESET=asan-ubsan $(if $(filter 1,$(ASAN_ALL)),,TEST_EXCLUDE=^slurm_sweep)

# The haptics tests (servo loop, lock-free buffers, UDP device: the tests named Haptics*) under
# ThreadSanitizer; only their test executable is built. A race report fails the run.
test-tsan: deps
	@cmake --preset tsan >/dev/null
	@cmake --build build/tsan -j$(JOBS) --target sb_common_tests
	@TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
		ctest --test-dir build/tsan --output-on-failure -j$(JOBS) --timeout 900 -R '^Haptics' --no-tests=error

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

# The particle (DEM) references in experiments/dem/references/, regenerated from the scenes with
# LAMMPS (installed by deps.sh): every case x seed of experiments/dem/{cases,material}.toml.
# ENGINE=slurm runs them as one job array (SLURM_PARTITION, SLURM_TIME as for reproduce);
# DEM_RANKS > 1 runs each under mpirun; DEM_CASES="pile box_blade" a subset. Takes CPU hours'
# fraction: the runs print their LAMMPS CPU time. `make reproduce` only reads the stored files.
DEM_RANKS ?= 1
dem: deps
	@$(PYTHON) experiments/dem/run_dem.py --engine $(ENGINE) --jobs $(JOBS) --ranks $(DEM_RANKS) \
		$(if $(DEM_CASES),--cases $(DEM_CASES),) $(if $(SLURM_PARTITION),--partition $(SLURM_PARTITION),) \
		$(if $(SLURM_TIME),--time $(SLURM_TIME),)

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
