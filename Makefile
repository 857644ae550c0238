# Entry points of the project. `make test` on a fresh clone installs, builds and tests.
SHELL := /bin/bash
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
WS := $(ROOT)/.ws
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
# The python3 on some PATHs is not Debian's; catkin needs Debian's (catkin_pkg, empy).
PYTHON := /usr/bin/python3
CATKIN_ARGS := -DPYTHON_EXECUTABLE=$(PYTHON) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DCATKIN_ENABLE_TESTING=ON
SOURCES = $(shell cd $(ROOT) && git ls-files -co --exclude-standard -- '*.cpp' '*.h' | grep -v '^\.ws/')

.PHONY: all setup build test bench demo format format-check lint clean help

all: build

help:
	@echo "make setup         install Debian packages, create the catkin workspace (.ws/)"
	@echo "make build         build everything (BUILD_TYPE=$(BUILD_TYPE))"
	@echo "make test          setup + build + every gtest and rostest; ends 'N passed, N failed'"
	@echo "make bench         setup + build + benchmarks (timings, memory, accuracy tables)"
	@echo "make demo          setup + build + a synthetic tree scanned, modeled and scored -> results/"
	@echo "make format        clang-format the sources in place"
	@echo "make format-check  fail on any badly formatted source; check the core has no ROS"
	@echo "make clean         remove the build (keeps installed packages)"

setup: $(WS)/.setup-stamp

$(WS)/.setup-stamp: scripts/setup.sh scripts/debian-packages.txt
	bash scripts/setup.sh
	touch $@

build: setup
	cd $(WS) && catkin_make $(CATKIN_ARGS) -j$(JOBS)

test: build
	rm -rf $(WS)/build/test_results
	$(MAKE) -C $(WS)/build -j$(JOBS) tests
	-$(MAKE) -C $(WS)/build -j1 run_tests
	$(PYTHON) scripts/test_summary.py $(WS)/build/test_results

bench: build
	$(MAKE) -C $(WS)/build -j$(JOBS) benchmarks
	bash scripts/run_benchmarks.sh $(WS)/devel/lib/dormant_tree_modeling

demo: build
	bash scripts/demo.sh

format: setup
	clang-format -i $(SOURCES)

format-check: setup
	clang-format --dry-run --Werror $(SOURCES)
	bash scripts/check_layering.sh

lint: format-check

clean:
	rm -rf $(WS)/build $(WS)/devel
