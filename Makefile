# Thin wrapper over CMake presets. `make demo` and `make test` install any
# missing Debian packages first (scripts/install-deps.sh, idempotent).
#   make demo   - Release build, then the main job on the built-in default scene
#   make test   - Release build, the clang-format check, then the whole ctest suite (non-zero on failure)
#   make format - clang-format every C++ file in place
#   make asan   - ASan + UBSan build of the tests, then run them
#   make bench  - benchmarks that print figures and write plots under build/bench
# CI=true (as in .ci/run) adds -Werror.

CMAKE_FLAGS :=
ifeq ($(CI),true)
  CMAKE_FLAGS += -DIBR_WERROR=ON
endif
DEMO_OUT ?= build/demo

.PHONY: deps configure build demo test asan bench clean format

deps:
	@bash scripts/install-deps.sh

configure: deps
	cmake --preset release $(CMAKE_FLAGS)

build: configure
	cmake --build --preset release

demo: build
	build/bin/ibr demo --out $(DEMO_OUT)

test: build
	cmake --build --preset release --target format-check
	ctest --preset release

asan: deps
	cmake --preset asan $(CMAKE_FLAGS)
	cmake --build --preset asan
	ctest --preset asan

format: configure
	cmake --build --preset release --target format

bench: build
	build/bin/ibr bench fillrate

clean:
	rm -rf build build-debug build-asan
