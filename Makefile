# Two commands for a fresh machine: `make demo` and `make test`. Both set up first if needed:
# the demo only what it runs, the tests (and lint, bench) their tools on top (requirements-dev.txt).
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.setup-complete
DEV_STAMP := $(VENV)/.dev-complete
PACKAGES := haptic_util haptic_contract collision_engine force_renderer haptic_wand_driver simulated_operator \
	haptic_bringup teleop_protocol teleop_leader robot_site link_emulator ultrasound_sim site_gateway
SETUP_INPUTS := requirements.txt constraints.txt pyproject.toml tools/setup_venv.sh \
	tools/fix_wheel_cmake_paths.py \
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

.PHONY: setup demo report test fuzz bench lint clean
setup: $(DEV_STAMP)

$(STAMP): $(SETUP_INPUTS)
	tools/setup_venv.sh $(VENV)
	touch $@

$(DEV_STAMP): $(STAMP) requirements-dev.txt
	tools/setup_venv.sh --dev $(VENV)
	touch $@

# The demo's experiments over ROS 2, then the report: from their bags, and from the benchmarks'
# last stored results (bench/results/, which `make bench` refreshes; nothing is benchmarked here).
demo: $(STAMP)
	$(VENV)/bin/demo --out build/demo
	$(PY) report_generator/report.py --demo-dir build/demo --out report

# The report again from the last demo's bags and the stored results (after `make bench`).
report: $(STAMP)
	$(PY) report_generator/report.py --demo-dir build/demo --out report

# Deterministic: Hypothesis's ci profile draws the same examples on every run. The tests that
# start no ROS node or process and time nothing share both cores; then the others, one at a
# time (tests/conftest.py marks them serial).
test: $(DEV_STAMP)
	export CI=$${CI:-1}; \
	$(PY) -m pytest -q -n 2 -m 'not serial' --durations=10 tests; shared=$$?; \
	$(PY) -m pytest -q -m serial --durations=15 tests; alone=$$?; \
	exit $$(( shared || alone ))

# Fresh random examples, ten times as many, for the property tests (no ROS processes).
fuzz: $(DEV_STAMP)
	HYPOTHESIS_PROFILE=fuzz $(PY) -m pytest -q tests --ignore=tests/integration

# Every benchmark; the report's are stored in bench/results/ (not with --quick).
bench: $(DEV_STAMP)
	$(PY) bench/run_all.py $(ARGS)

lint: $(DEV_STAMP)
	$(PY) -m pytest -q tests/test_lint.py

clean:
	rm -rf build $(VENV)
