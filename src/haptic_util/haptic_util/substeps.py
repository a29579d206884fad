"""A simulated device's clock: fixed substeps counted from its first reading, never back.

The simulated wand and the simulated robot each integrate in fixed substeps and are read with
the time of the tick. Both start their clock at the first reading, and refuse a time before the
last substep done: a clock gone back would have to undo the physics already run.
"""
import math
from typing import Optional

__all__ = ['substeps_due']


def substeps_due(now: float, start: Optional[float], steps_done: int, step: float,
                 who: str) -> tuple[float, int]:
    """Return the clock's start and how many substeps of it lie at or before ``now`` (s).

    ``start`` is None before the first reading, which starts the clock at ``now``; ``step`` is
    the substep (s). Raises ValueError, naming ``who``, if ``now`` is before the last of the
    ``steps_done`` substeps.
    """
    if start is None:
        start = now
    last = start + steps_done * step
    if now < last:
        raise ValueError(f'{who}: now {now!r} s is before the last state ({last!r} s); '
                         'the clock must not go back')
    return start, math.floor((now - start) / step + 1e-9)
