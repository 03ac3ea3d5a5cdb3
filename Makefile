# Two commands on a fresh Debian machine:
#   make demo   install what is missing, build, run the main job on bundled data (out/)
#   make test   install what is missing, build, run the test suite
BUILD ?= build
JOBS  ?= 2

.PHONY: setup build demo test bench clean

setup:
	bash scripts/setup.sh

build: setup
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DPIC_BUILD_TESTS=ON
	cmake --build $(BUILD) -j$(JOBS)

demo: build
	bash scripts/demo.sh $(BUILD)/pic

test: build
	ctest --test-dir $(BUILD) --output-on-failure -j$(JOBS)

bench:
	bash scripts/setup.sh --bench
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release -DPIC_BUILD_TESTS=ON -DPIC_BUILD_BENCH=ON
	cmake --build $(BUILD) -j$(JOBS)
	bash bench/run.sh $(BUILD)

clean:
	rm -rf $(BUILD) out
