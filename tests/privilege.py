"""Processes with and without the right to real-time scheduling (SCHED_FIFO)."""
import os
import shutil

__all__ = ['ROOT', 'WITHOUT_REALTIME']

ROOT = os.geteuid() == 0  # CI runs as root
# A command's prefix that takes the right away, as a user without an rtprio limit has it: an
# rtprio limit of 0 (prlimit), and as root no CAP_SYS_NICE either (util-linux's setpriv).
WITHOUT_REALTIME = ('prlimit', '--rtprio=0', *(
    ('setpriv', '--bounding-set', '-sys_nice', '--inh-caps', '-sys_nice') if ROOT else ()))
_TOOLS = ('prlimit', 'setpriv') if ROOT else ('prlimit',)
assert all(shutil.which(tool) for tool in _TOOLS), f'util-linux is missing: {_TOOLS} needed'
