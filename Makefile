# Two commands on a fresh Debian machine:
#   make demo   install what is missing, build, run the main job on bundled data (out/)
#   make test   install what is missing, build, run the test suite
BUILD ?= build
JOBS  ?= 2

.PHONY: setup build demo test test-sanitize bench fuzz clean

setup:
	bash scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DPIC_BUILD_TESTS=ON
	cmake --build $(BUILD) -j$(JOBS)

# The demo needs the library and the command-line tool only: no test is built for it.
demo: setup
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j$(JOBS) --target pic_cli
	bash scripts/demo.sh $(BUILD)/pic

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

# The test suite once more with AddressSanitizer, UndefinedBehaviorSanitizer and the internal
# invariant checks (PIC_ENABLE_ASSERTS) in build-sanitize; CI runs it after `make test`.
SAN_BUILD ?= build-sanitize
test-sanitize: setup
	cmake -S . -B $(SAN_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" \
	  -DPIC_BUILD_TESTS=ON \
	  -DPIC_SANITIZE=ON -DPIC_ENABLE_ASSERTS=ON
	cmake --build $(SAN_BUILD) -j$(JOBS)
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --test-dir $(SAN_BUILD) --output-on-failure -j$(JOBS)

bench:
	bash scripts/setup.sh --bench
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DPIC_BUILD_TESTS=ON -DPIC_BUILD_BENCH=ON
	cmake --build $(BUILD) -j$(JOBS)
	bash bench/run.sh $(BUILD)

# Fuzzing (docs/reliability.md): libFuzzer + ASan/UBSan harnesses built with clang in build-fuzz,
# each run for FUZZ_RUNS executions (glTF: a tenth).
FUZZ_BUILD ?= build-fuzz
FUZZ_RUNS  ?= 1000000
fuzz:
	bash scripts/setup.sh --fuzz
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DPIC_BUILD_FUZZ=ON -DPIC_BUILD_TESTS=OFF -DPIC_BUILD_CLI=OFF
	cmake --build $(FUZZ_BUILD) -j$(JOBS)
	bash fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_RUNS)

clean:
	rm -rf $(BUILD) out
