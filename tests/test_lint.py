"""The repository passes the linters ament runs on ROS 2 packages: flake8 and pep257."""
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SOURCES = ['src', 'tests', 'bench', 'ground_truth', 'report_generator', 'tools']


@pytest.mark.parametrize('linter', ['flake8', 'pydocstyle'])
def test_linter_is_clean(linter):
    result = subprocess.run([sys.executable, '-m', linter, *SOURCES], cwd=ROOT,
                            capture_output=True, text=True)
    assert result.returncode == 0, f'{linter} found:\n{result.stdout}{result.stderr}'
