"""The bench scripts are plain files in ``bench/``, not a package: put them on the path."""
import pathlib
import sys

BENCH = pathlib.Path(__file__).resolve().parents[2] / 'bench'
if str(BENCH) not in sys.path:
    sys.path.append(str(BENCH))
