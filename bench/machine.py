"""What every benchmark prints first: the machine, and the versions its figures depend on."""
from importlib.metadata import PackageNotFoundError, version
import os
import platform
import time

__all__ = ['cpu_model', 'describe', 'line']


def cpu_model() -> str:
    """Return the CPU's model name, from /proc/cpuinfo where there is one."""
    try:
        with open('/proc/cpuinfo') as cpuinfo:
            return next(line.split(':', 1)[1].strip() for line in cpuinfo
                        if line.startswith('model name'))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def describe(*packages: str) -> dict:
    """Return the CPU model, core count, Python, and the version of each of ``packages``."""
    info = {'cpu': cpu_model(), 'cores': os.cpu_count(), 'python': platform.python_version()}
    for package in packages:
        try:
            info[package] = version(package)
        except PackageNotFoundError:
            info[package] = 'not installed'
    return info


def line(*packages: str) -> str:
    """Return ``describe`` as one line, with the date."""
    info = describe(*packages)
    return (', '.join(f'{key} {value}' for key, value in info.items())
            + f', {time.strftime("%Y-%m-%d %H:%M %Z")}')
