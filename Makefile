# Two commands for a fresh machine: `make demo` and `make test`. Both set up first if needed.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.setup-complete
PACKAGES := haptic_util collision_engine force_renderer haptic_wand_driver haptic_bringup remote_probe \
	site_gateway
SETUP_INPUTS := requirements.txt constraints.txt tools/setup_venv.sh tools/fix_wheel_cmake_paths.py \
	$(wildcard src/msgs/*.txt src/msgs/*.xml src/msgs/msg/*.msg) \
	$(foreach p,$(PACKAGES),$(wildcard src/$(p)/setup.py src/$(p)/setup.cfg src/$(p)/package.xml \
	  src/$(p)/config/* src/$(p)/launch/* src/$(p)/scenes/* src/$(p)/scenes/meshes/*))

# Local DDS only, and a domain of our own, for everything make runs.
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
export ROS_DOMAIN_ID ?= 42
export ROS_LOG_DIR := $(CURDIR)/build/ros_log
export ROS_HOME := $(CURDIR)/build/ros_home
export AMENT_PREFIX_PATH := $(CURDIR)/$(VENV)
unexport _ROS_WHEELS_BOOTSTRAP_COMPLETE

.PHONY: setup demo test fuzz bench lint clean
setup: $(STAMP)

$(STAMP): $(SETUP_INPUTS)
	tools/setup_venv.sh $(VENV)
	touch $@

demo: $(STAMP)
	$(VENV)/bin/demo --out build/demo
	$(PY) bench/report.py --demo-dir build/demo --out report

# Deterministic: Hypothesis's ci profile draws the same examples on every run.
test: $(STAMP)
	CI=$${CI:-1} $(PY) -m pytest -q tests

# Fresh random examples, ten times as many, for the property tests (no ROS processes).
fuzz: $(STAMP)
	HYPOTHESIS_PROFILE=fuzz $(PY) -m pytest -q tests --ignore=tests/integration

bench: $(STAMP)
	$(PY) bench/run_all.py $(ARGS)

clean:
	rm -rf build $(VENV)
