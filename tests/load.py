"""Cores kept busy by other processes: a sonographer's workstation is never idle (issue 24)."""
import contextlib
import subprocess
import sys

__all__ = ['hogged']

HOG = 'while True: pass'


@contextlib.contextmanager
def hogged(cores: int = 1):
    """Keep ``cores`` cores busy with processes of their own while the block runs."""
    hogs = [subprocess.Popen([sys.executable, '-S', '-c', HOG]) for _ in range(cores)]
    try:
        yield hogs
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
