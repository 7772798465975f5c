# The two commands of the README: `make demo` and `make test`. Everything else is a building block.
JOBS      ?= $(shell nproc)
BUILD     ?= build
ASAN      ?= build-asan
TSAN      ?= build-tsan
GENERATOR := $(shell command -v ninja >/dev/null 2>&1 && echo "-G Ninja")
# ccache (when installed) keys objects on paths relative to the checkout, so a fresh clone elsewhere on the
# same machine reuses what an earlier build compiled (except unity batches, which name their sources by
# absolute path: those are reused by a clone at the same place).
export CCACHE_BASEDIR ?= $(CURDIR)
export CCACHE_MAXSIZE ?= 20G
CTEST     := ctest --output-on-failure --timeout 600 -j $(JOBS)

.PHONY: deps build build-rigcal test test-release test-asan test-tsan test-fuzz demo bench fuzz clean

deps:
	@scripts/install-deps

# A build folder `make test` creates compiles each library in unity batches (RIGCAL_UNITY_BUILD, as the
# sanitizer builds do): it builds everything from scratch. One that `make build` or `make demo` creates keeps
# one object per source, so that an edit recompiles only its file.
RELEASE_UNITY ?= OFF
$(BUILD)/build.ninja $(BUILD)/Makefile:
	cmake -S . -B $(BUILD) $(GENERATOR) -DCMAKE_BUILD_TYPE=Release -DRIGCAL_UNITY_BUILD=$(RELEASE_UNITY)

build: deps $(BUILD)/$(if $(GENERATOR),build.ninja,Makefile)
	cmake --build $(BUILD) -j $(JOBS)

# The demo needs only the executable: it starts simulating as soon as `rigcal` links.
build-rigcal: deps $(BUILD)/$(if $(GENERATOR),build.ninja,Makefile)
	cmake --build $(BUILD) -j $(JOBS) --target rigcal

# The whole suite: the Release build, the ASan+UBSan build, the TSan build, then every fuzz harness for
# a bounded time (clang, ASan+UBSan).
FUZZ_CI_SECONDS ?= 10
test: deps test-release test-asan test-tsan test-fuzz
test: RELEASE_UNITY = ON

test-release: build
	cd $(BUILD) && $(CTEST)

# clang for both sanitizer builds: it compiles this code base's instrumented objects in about half of
# GCC's CPU time (calibrate_command.cpp with ASan+UBSan: 17.8 s against 32.0 s). Both build the libraries
# and the executable as unity batches (RIGCAL_UNITY_BUILD): from scratch, 2.3x less CPU for them.
test-asan: deps
	CXX=clang++ cmake -S . -B $(ASAN) $(GENERATOR) -DCMAKE_BUILD_TYPE=Debug -DRIGCAL_SANITIZE=address \
	  -DRIGCAL_UNITY_BUILD=ON
	cmake --build $(ASAN) -j $(JOBS)
	cd $(ASAN) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 $(CTEST)

# clang: GCC's TSan refuses the standalone fences moodycamel's queue relies on. Only the suites that run
# threads or processes against each other (RIGCAL_CONCURRENT_TESTS in tests/CMakeLists.txt) are built here.
test-tsan: deps
	CXX=clang++ cmake -S . -B $(TSAN) $(GENERATOR) -DCMAKE_BUILD_TYPE=Debug -DRIGCAL_SANITIZE=thread \
	  -DRIGCAL_UNITY_BUILD=ON
	cmake --build $(TSAN) -j $(JOBS)
	cd $(TSAN) && TSAN_OPTIONS="halt_on_error=1 suppressions=$(CURDIR)/tests/tsan.supp" $(CTEST)

demo: build-rigcal
	@scripts/demo $(BUILD)

bench: build
	@scripts/run-benchmarks $(BUILD)

test-fuzz: deps
	@scripts/run-fuzzers $(FUZZ_CI_SECONDS)

# Every libFuzzer harness (clang, ASan+UBSan) for FUZZ_SECONDS each (default 30), in build-fuzz.
fuzz: deps
	@scripts/run-fuzzers $(FUZZ_SECONDS)

clean:
	rm -rf $(BUILD) $(ASAN) $(TSAN) build-fuzz
