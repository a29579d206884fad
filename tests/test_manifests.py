"""Every package declares in its ``package.xml`` what its code imports, so rosdep and colcon work.

A ROS 2 user builds one package with its dependencies (``colcon build --packages-up-to``, rosdep
install), from what the manifests say: an import that is not declared works here, where one venv
holds everything, and breaks there. The imports are read from the code (its syntax tree, every
import statement, at any depth), not from a list kept by hand.
"""
import ast
import pathlib
import sys
import xml.etree.ElementTree as ElementTree

import pytest

SRC = pathlib.Path(__file__).resolve().parents[1] / 'src'
PACKAGES = sorted(path.parent.name for path in SRC.glob('*/package.xml')
                  if (path.parent / 'setup.py').exists())
# A Python module's rosdep key, where it is not the module's own name (a ROS package's is).
ROSDEP_KEYS = {
    'numpy': 'python3-numpy', 'scipy': 'python3-scipy', 'yaml': 'python3-yaml',
    'numba': 'python3-numba', 'trimesh': 'python3-trimesh', 'fcl': 'python3-fcl',
    'psutil': 'python3-psutil', 'cryptography': 'python3-cryptography',
    'rosbags': 'python3-rosbags-pip', 'mcap': 'python3-mcap-pip',
    'zenoh': 'python3-eclipse-zenoh-pip',
    'matplotlib': 'python3-matplotlib', 'rtree': 'python3-rtree', 'coal': 'python3-coal-pip',
}


def manifest(package: str) -> list:
    """Return the keys ``package.xml`` declares for running the package (exec or both)."""
    root = ElementTree.parse(SRC / package / 'package.xml').getroot()
    return [element.text.strip() for element in root
            if element.tag in ('depend', 'exec_depend')]


def imported(package: str) -> set:
    """Return the top-level modules the package's installed code imports (not the stdlib)."""
    folders = [SRC / package / package, SRC / package / 'launch']
    modules = set()
    for path in (path for folder in folders if folder.is_dir() for path in folder.rglob('*.py')):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                modules.update(alias.name.split('.')[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                modules.add(node.module.split('.')[0])
    return {module for module in modules
            if module not in sys.stdlib_module_names and module != package}


@pytest.mark.parametrize('package', PACKAGES)
def test_every_import_is_declared_once(package):
    declared = manifest(package)
    needed = {ROSDEP_KEYS.get(module, module) for module in imported(package)}
    assert sorted(needed - set(declared)) == [], f'{package}/package.xml lacks these'
    assert len(declared) == len(set(declared)), f'{package}/package.xml declares one twice'


def test_the_manifests_were_read():
    """What the checks above compare is there: each package imports something of ROS."""
    assert {'haptic_util', 'collision_engine', 'robot_site'} <= set(PACKAGES)
    assert all('rclpy' in manifest(package) for package in PACKAGES if 'rclpy' in
               imported(package))
    assert 'numpy' in imported('collision_engine')
