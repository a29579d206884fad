#!/usr/bin/env bash
# Sets up everything the toolkit needs on a fresh clone: the venv with pinned wheels (ROS 2 Jazzy
# from PyPI included), the CMake path fix those wheels need, the haptic_msgs interface package
# built into the venv, and the Python packages installed (code editable, data files copied).
# Re-running it is safe. Usage: tools/setup_venv.sh [VENV_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
venv=${1:-.venv}
python=${PYTHON:-python3}

# The wheels' bootstrapper re-execs Python with LD_LIBRARY_PATH set; a marker leaked from another
# venv would make ours skip that step.
unset _ROS_WHEELS_BOOTSTRAP_COMPLETE
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST

step() { printf '[setup] %s\n' "$*"; }

if [ ! -x "$venv/bin/python" ]; then
  step "creating venv $venv"
  "$python" -m venv "$venv"
fi
venv=$(cd "$venv" && pwd)
pip=("$venv/bin/python" -m pip --disable-pip-version-check --no-input)
mkdir -p build

step "installing pinned dependencies (requirements.txt, constraints.txt)"
# (Some machines list missing local indexes in their pip config; hide that noise, keep errors.)
"${pip[@]}" install -q -r requirements.txt -c constraints.txt 2> >(grep -v 'is ignored: it is neither' >&2)

step "pointing the wheels' CMake exports at this interpreter"
"$venv/bin/python" tools/fix_wheel_cmake_paths.py

step "building haptic_msgs into the venv"
export AMENT_PREFIX_PATH=$venv
export PATH=$venv/bin:$PATH
cmake -S src/msgs -B build/haptic_msgs -DCMAKE_INSTALL_PREFIX="$venv" -DBUILD_TESTING=OFF \
  -DPython3_EXECUTABLE="$venv/bin/python" >build/haptic_msgs.cmake.log 2>&1 \
  || { cat build/haptic_msgs.cmake.log; exit 1; }
make -C build/haptic_msgs -j2 install >build/haptic_msgs.make.log 2>&1 \
  || { tail -50 build/haptic_msgs.make.log; exit 1; }

for pkg in haptic_util collision_engine force_renderer haptic_wand_driver haptic_bringup \
    remote_probe site_gateway; do
  step "installing $pkg"
  # compat mode puts src/<pkg> on sys.path, so a tests/<pkg>/ folder can never shadow it.
  "${pip[@]}" install -q --no-deps --no-build-isolation --use-pep517 -e "src/$pkg" \
    --config-settings editable_mode=compat \
    2> >(grep -v 'is ignored: it is neither' >&2)
  # PEP 660 editable installs skip data_files: install the ament index marker, package.xml,
  # config, launch and scene files into <venv>/share the way colcon would.
  (cd "src/$pkg" && "$venv/bin/python" -W ignore setup.py -q install_data -d "$venv" >/dev/null)
done

"$venv/bin/python" -c "import rclpy, haptic_msgs.msg, haptic_util, collision_engine, force_renderer, \
haptic_wand_driver, haptic_bringup, remote_probe, site_gateway, zenoh" || { echo "[setup] import check failed"; exit 1; }
step "compiling the collision kernels once (numba caches them for every later start)"
"$venv/bin/python" -c "
import pathlib
from collision_engine import load_scene
for scene in sorted(pathlib.Path('src/collision_engine/scenes').glob('*.yaml')):
    load_scene(scene)
"
step "done: $venv"
