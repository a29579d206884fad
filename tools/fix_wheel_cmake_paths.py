"""Rewrite the wheel factory's include paths baked into the ROS wheels' CMake exports.

The ros-jazzy wheels ship ``*_rosidl_generator_pyExport.cmake`` files that point at
``/opt/python/cp311-cp311`` (the interpreter they were built with). CMake then refuses to build
any interface package against them ("Imported target ... includes non-existent path"). This
script points them at this interpreter's include directory and numpy's. Idempotent.
"""
import pathlib
import re
import sys
import sysconfig

import numpy

FACTORY_PYTHON_INCLUDE = re.compile(r"/opt/python/cp3\d+-cp3\d+/include/python3\.\d+")
FACTORY_NUMPY_INCLUDE = re.compile(
    r"/opt/python/cp3\d+-cp3\d+/lib/python3\.\d+/site-packages/numpy/(?:_core|core)/include")


def fix(prefix: pathlib.Path) -> int:
    python_include = sysconfig.get_paths()["include"]
    numpy_include = numpy.get_include()
    changed = 0
    for export in (prefix / "share").glob("*/cmake/*_rosidl_generator_pyExport.cmake"):
        text = export.read_text()
        fixed = FACTORY_NUMPY_INCLUDE.sub(numpy_include, text)
        fixed = FACTORY_PYTHON_INCLUDE.sub(python_include, fixed)
        if fixed != text:
            export.write_text(fixed)
            changed += 1
    return changed


if __name__ == "__main__":
    print(f"fixed {fix(pathlib.Path(sys.prefix))} wheel CMake export(s) in {sys.prefix}")
