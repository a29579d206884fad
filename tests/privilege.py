"""Processes with and without the right to real-time scheduling (SCHED_FIFO)."""
import os
import shutil

__all__ = ['ROOT', 'WITHOUT_REALTIME']

ROOT = os.geteuid() == 0  # CI runs as root
# A command's prefix that takes the right away, as a user without an rtprio limit has it:
# no CAP_SYS_NICE (util-linux's setpriv), and an rtprio limit of 0 (prlimit).
WITHOUT_REALTIME = ('prlimit', '--rtprio=0', 'setpriv', '--bounding-set', '-sys_nice',
                    '--inh-caps', '-sys_nice')
assert all(shutil.which(tool) for tool in ('prlimit', 'setpriv')), 'util-linux is missing'
