# Entry points of the project. `make test` on a fresh clone installs, builds and tests.
SHELL := /bin/bash
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
# Standalone catkin build of this one package: .build/cmake (CMake tree), .build/devel (devel
# space; `source .build/devel/setup.bash`). Not build/: rosrun ignores a package's build/.
BUILD := $(ROOT)/.build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
# The python3 on some PATHs is not Debian's; catkin needs Debian's (catkin_pkg, empy).
PYTHON := /usr/bin/python3
CMAKE_ARGS := -DPYTHON_EXECUTABLE=$(PYTHON) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DCATKIN_ENABLE_TESTING=ON \
	-DCATKIN_DEVEL_PREFIX=$(BUILD)/devel
SOURCES = $(shell cd $(ROOT) && git ls-files -co --exclude-standard -- '*.cpp' '*.h')

.PHONY: all setup build test bench fuzz demo config format format-check lint clean help

all: build

help:
	@echo "make setup         install the Debian packages the project needs"
	@echo "make build         build everything (BUILD_TYPE=$(BUILD_TYPE))"
	@echo "make test          setup + build + every gtest and rostest; ends 'N passed, N failed'"
	@echo "make bench         setup + build + benchmarks (timings, memory, accuracy tables)"
	@echo "make fuzz          libFuzzer: LMS111 bytes and recordings, cloud/JSON files, Ensemble replies (FUZZ_SECONDS=60 each)"
	@echo "make demo          setup + build + a synthetic tree scanned, modeled and scored -> results/"
	@echo "make config        rewrite config/*.yaml and docs/configuration.md from the parameter tables"
	@echo "make format        clang-format the sources in place"
	@echo "make format-check  fail on any badly formatted source; check the core has no ROS"
	@echo "make clean         remove the build (keeps installed packages)"

setup: $(BUILD)/.setup-stamp

$(BUILD)/.setup-stamp: scripts/setup.sh scripts/debian-packages.txt
	bash scripts/setup.sh
	mkdir -p $(BUILD)
	touch $@

build: setup
	cmake -S $(ROOT) -B $(BUILD)/cmake $(CMAKE_ARGS) > $(BUILD)/cmake.log || (cat $(BUILD)/cmake.log; false)
	$(MAKE) -C $(BUILD)/cmake -j$(JOBS)

test: build
	rm -rf $(BUILD)/cmake/test_results
	$(MAKE) -C $(BUILD)/cmake -j$(JOBS) tests
	# Debian's python3 first: ROS's scripts (roslaunch-check) start with "env python3".
	-PATH=/usr/bin:$$PATH $(MAKE) -C $(BUILD)/cmake -j1 run_tests
	$(PYTHON) scripts/test_summary.py $(BUILD)/cmake/test_results

bench: build
	$(MAKE) -C $(BUILD)/cmake -j$(JOBS) benchmarks
	bash scripts/run_benchmarks.sh $(BUILD)/devel/lib/dormant_tree_modeling

fuzz:
	bash scripts/fuzz.sh

demo: build
	bash scripts/demo.sh

config: build
	$(BUILD)/devel/lib/dormant_tree_modeling/config_reference --write $(ROOT)

format: setup
	clang-format -i $(SOURCES)

format-check: setup
	clang-format --dry-run --Werror $(SOURCES)
	bash scripts/check_layering.sh

lint: format-check

clean:
	rm -rf $(BUILD)/cmake $(BUILD)/devel $(BUILD)/cmake.log
