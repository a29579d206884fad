#!/usr/bin/env bash
# Sets up everything the toolkit and its demo need on a fresh clone: the venv with pinned wheels
# (ROS 2 Jazzy from PyPI included), the CMake path fix those wheels need, the haptic_msgs
# interface package built into the venv, the Python packages installed (code editable, data files
# copied), and the collision kernels compiled. With --dev, it then adds what the tests, lint and
# benchmarks need (requirements-dev.txt) to that venv. Re-running it is safe; each step says how
# long it took. Usage: tools/setup_venv.sh [--dev] [VENV_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
dev=false
if [ "${1:-}" = --dev ]; then dev=true; shift; fi
venv=${1:-.venv}
python=${PYTHON:-python3}

# The wheels' bootstrapper re-execs Python with LD_LIBRARY_PATH set; a marker leaked from another
# venv would make ours skip that step.
unset _ROS_WHEELS_BOOTSTRAP_COMPLETE
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST

now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.0f", b - a }'; }
setup_started=$(now)
step_started=
step_name=
finish_step() {
  if [ -n "$step_name" ]; then printf '[setup]     %s: %s s\n' "$step_name" "$(since "$step_started")"; fi
  step_name=
}
step() { finish_step; printf '[setup] %s ...\n' "$1"; step_name=$1; step_started=$(now); }
# pip compiles every module of every wheel to bytecode by default (half its time here); Python
# compiles the ones a run imports, once, on first import instead.
# (Some machines list missing local indexes in their pip config; hide that noise, keep errors.)
pip_install() {
  "$venv/bin/python" -m pip --disable-pip-version-check --no-input install -q --no-compile "$@" \
    2> >(grep -v 'is ignored: it is neither' >&2)
}

if [ ! -x "$venv/bin/python" ]; then
  step "creating venv $venv"
  "$python" -m venv "$venv"
fi
venv=$(cd "$venv" && pwd)
mkdir -p build

if $dev; then
  step "installing the tests', lint's and benchmarks' tools (requirements-dev.txt)"
  pip_install -r requirements-dev.txt -c constraints.txt
  finish_step
  printf '[setup] done in %s s: %s\n' "$(since "$setup_started")" "$venv"
  exit 0
fi

step "installing pinned dependencies (requirements.txt, constraints.txt)"
pip_install -r requirements.txt -c constraints.txt

step "pointing the wheels' CMake exports at this interpreter"
"$venv/bin/python" tools/fix_wheel_cmake_paths.py
finish_step

# haptic_msgs builds (C and CMake, most of it waiting on the compiler) while the Python packages
# install: installing them needs no message.
build_msgs() {
  local started
  started=$(now)
  export AMENT_PREFIX_PATH=$venv
  export PATH=$venv/bin:$PATH
  cmake -S src/msgs -B build/haptic_msgs -DCMAKE_INSTALL_PREFIX="$venv" -DBUILD_TESTING=OFF \
    -DPython3_EXECUTABLE="$venv/bin/python" >build/haptic_msgs.cmake.log 2>&1 \
    || { cat build/haptic_msgs.cmake.log; return 1; }
  make -C build/haptic_msgs -j2 install >build/haptic_msgs.make.log 2>&1 \
    || { tail -50 build/haptic_msgs.make.log; return 1; }
  printf '[setup]     haptic_msgs built: %s s\n' "$(since "$started")"
}
printf '[setup] building haptic_msgs into the venv, beside the next steps ...\n'
build_msgs &
msgs=$!

packages=(haptic_util haptic_contract collision_engine force_renderer haptic_wand_driver
  simulated_operator haptic_bringup teleop_protocol teleop_leader robot_site link_emulator
  ultrasound_sim site_gateway)
step "installing the toolkit's packages: ${packages[*]}; and ground_truth, bench, report_generator"
# compat mode puts src/<pkg> on sys.path, so a tests/<pkg>/ folder can never shadow it; and, for
# the repository's own packages (pyproject.toml: the ground truth, the benchmarks, the report),
# the repository's root.
editable=()
for pkg in "${packages[@]}"; do editable+=(-e "src/$pkg"); done
pip_install --no-deps --no-build-isolation --use-pep517 --config-settings editable_mode=compat \
  "${editable[@]}" -e .
for pkg in "${packages[@]}"; do
  # PEP 660 editable installs skip data_files: install the ament index marker, package.xml,
  # config, launch and scene files into <venv>/share the way colcon would.
  (cd "src/$pkg" && "$venv/bin/python" -W ignore setup.py -q install_data -d "$venv" >/dev/null)
done

# The engine's status codes are CollisionState's own constants (haptic_contract), so its
# kernels compile once the messages are built.
step "waiting for haptic_msgs"
wait "$msgs" || { echo "[setup] building haptic_msgs failed"; exit 1; }

step "compiling the collision kernels (numba caches them per user for every later start)"
"$venv/bin/python" -c "
import pathlib
from collision_engine import load_scene
for scene in sorted(pathlib.Path('src/collision_engine/scenes').glob('*.yaml')):
    load_scene(scene)
"
"$venv/bin/python" -c "import rclpy, haptic_msgs.msg, haptic_util, haptic_contract, collision_engine, \
force_renderer, haptic_wand_driver, simulated_operator, haptic_bringup, teleop_protocol, teleop_leader, \
robot_site, link_emulator, ultrasound_sim, site_gateway, zenoh, ground_truth, bench, report_generator" \
  || { echo "[setup] import check failed"; exit 1; }
finish_step
printf '[setup] done in %s s: %s\n' "$(since "$setup_started")" "$venv"
