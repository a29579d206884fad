"""The simulated operator's script, by name: an experiment, holding still, or waypoints.

The experiments are the paper's three tapping ones and the probe sweep.

A name picks a script; the scene only tells the scripted hand where the object's surface is
(``project``), as the 3D view told the paper's operator.
"""
from pathlib import Path
from typing import Optional

from simulated_operator.scripts import (cuboid_face_tapping, cylinder_side_tapping,
                                        hand_dorsum_tapping, probe_sweep, Projection,
                                        ScriptError, WaypointScript)

__all__ = ['EXPERIMENTS', 'make_script', 'needs_scene']

EXPERIMENTS = {
    'cuboid': cuboid_face_tapping,
    'cylinder': cylinder_side_tapping,
    'hand': hand_dorsum_tapping,
    'probe': probe_sweep,
}
HOLD = 'hold'
HOLD_DURATION = 1.0  # [s] any positive length: a held target never moves


def needs_scene(name: str) -> bool:
    """Whether the script ``name`` taps a surface, so needs the scene's projection."""
    return name in EXPERIMENTS


def make_script(name: str, project: Optional[Projection] = None, *, start=(0.0, 0.0, 0.0)):
    """Build the script ``name``: an experiment, ``hold``, or a waypoint file (.yaml/.csv)."""
    if name in EXPERIMENTS:
        if project is None:
            raise ScriptError(f'experiment {name!r} needs a scene to tap')
        return EXPERIMENTS[name](project, start=start)
    if name == HOLD:
        return WaypointScript([0.0, HOLD_DURATION], [[*start, 0.0, 0.0]] * 2)
    if Path(name).suffix in ('.yaml', '.yml', '.csv'):
        return WaypointScript.from_file(name)
    raise ScriptError(f'experiment {name!r} is not one of {[*EXPERIMENTS, HOLD]} '
                      'nor a waypoint file (.yaml, .yml, .csv)')
