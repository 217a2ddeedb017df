# Thin wrapper over CMake presets. `make demo` and `make test` install any
# missing Debian packages first (scripts/install-deps.sh, idempotent).
#   make demo   - Release build, then the main job on the built-in default scene
#   make test   - format check, Release build, then the whole ctest suite (non-zero on failure)
#   make format - clang-format every C++ file in place (make format-check: report differences)
#   make asan   - ASan + UBSan build of the tests (build-asan/), then the whole suite
#                 (every label but hard, as make test; test timeouts x5)
#   make bench  - benchmarks that print figures and write plots under build/bench
#   make report - the full `ibr report` (every bench) regenerating docs/report/ from scratch
#                 (report.md, report.html, PNGs, CSVs); long, run it on a quiet machine
#   make fuzz   - clang + libFuzzer + ASan/UBSan build of every parser's fuzz
#                 target (build-fuzz/), each run FUZZ_RUNS times (default 10^6)
#                 from the seed corpus; runs per parser in build-fuzz/fuzz-runs.txt
#                 (one line per parser, replaced when it runs again; FUZZ_TARGETS=...
#                 runs a subset).
#                 Not part of CI (about half an hour on 2 cores).
# CI=true (as in .ci/run) adds -Werror.

CMAKE_FLAGS :=
ifeq ($(CI),true)
  CMAKE_FLAGS += -DIBR_WERROR=ON
endif
DEMO_OUT ?= build/demo

FUZZ_RUNS ?= 1000000
SHARED_DATA ?= $(abspath ../shared/data)
# Every parser in the tree (capture/, core/, scene/) has one libFuzzer target;
# fuzz/CMakeLists.txt lists them and writes build-fuzz/fuzz-targets.txt, which
# `make fuzz` runs unless FUZZ_TARGETS names a subset.
FUZZ_TARGETS ?=

.PHONY: deps configure build demo test asan bench report fuzz clean format format-check

deps:
	@bash scripts/install-deps.sh

configure: deps
	cmake --preset release $(CMAKE_FLAGS)

build: configure
	cmake --build --preset release

# The demo needs only the ibr binary (shaders and scenes are embedded in it):
# building that target alone skips the tests and the viewer.
demo: configure
	cmake --build --preset release --target ibr
	build/bin/ibr demo --out $(DEMO_OUT)

test: format-check build
	ctest --preset release

asan: deps
	cmake --preset asan $(CMAKE_FLAGS)
	cmake --build --preset asan
	ctest --preset asan

format: configure
	cmake --build --preset release --target format

format-check: configure
	cmake --build --preset release --target format-check

fuzz: deps
	cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DIBR_FUZZ=ON -DIBR_BUILD_TESTS=OFF -DIBR_BUILD_VIEWER=OFF
	cmake --build build-fuzz --target fuzz_all
	build-fuzz/bin/fuzz_make_seeds build-fuzz/fuzz/corpus $(SHARED_DATA)
	build-fuzz/bin/fuzz_make_volume_seeds build-fuzz/fuzz/corpus
	@touch build-fuzz/fuzz-runs.txt
	@set -e; targets="$(FUZZ_TARGETS)"; [ -n "$$targets" ] || targets=$$(cat build-fuzz/fuzz-targets.txt); \
	for t in $$targets; do \
	  echo "fuzz: $$t, $(FUZZ_RUNS) runs"; \
	  build-fuzz/bin/fuzz_$$t -runs=$(FUZZ_RUNS) -seed=1 -max_len=4096 -rss_limit_mb=2048 -print_final_stats=1 \
	    build-fuzz/fuzz/corpus/$$t > build-fuzz/fuzz-$$t.log 2>&1 || { tail -40 build-fuzz/fuzz-$$t.log; exit 1; }; \
	  runs=$$(sed -n 's/^stat::number_of_executed_units: *//p' build-fuzz/fuzz-$$t.log); \
	  secs=$$(sed -n 's/^stat::average_exec_per_sec: *//p' build-fuzz/fuzz-$$t.log); \
	  sed -i "/^$$t /d" build-fuzz/fuzz-runs.txt; \
	  echo "$$t $$runs runs ($$secs/s)" | tee -a build-fuzz/fuzz-runs.txt; \
	done

bench: build
	build/bin/ibr bench fillrate

# docs/report/ is an earlier ibr output (its .ibr-output marker lists every
# file), so ibr replaces it whole: staged beside it, renamed into place.
report: build
	build/bin/ibr report --out docs/report

clean:
	rm -rf build build-debug build-asan build-fuzz
