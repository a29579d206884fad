"""Processes with and without the right to real-time scheduling (SCHED_FIFO)."""
import os
import shutil

__all__ = ['ROOT', 'WITHOUT_REALTIME']

ROOT = os.geteuid() == 0  # CI runs as root
# A command's prefix that takes the right away, as a user without an rtprio limit has it: an
# rtprio limit of 0 (prlimit), and as root no CAP_SYS_NICE either (util-linux's setpriv).
_PREFIXES = [('prlimit', '--rtprio=0'), *(
    [('setpriv', '--bounding-set', '-sys_nice', '--inh-caps', '-sys_nice')] if ROOT else [])]
WITHOUT_REALTIME = tuple(word for prefix in _PREFIXES for word in prefix)
assert all(shutil.which(prefix[0]) for prefix in _PREFIXES), 'util-linux is missing'
