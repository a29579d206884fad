"""The simulated operator: scripted targets and the hand that moves the simulated wand to them.

Pure Python and numpy. ``assembly.simulated_wand`` is the simulated wand held by this hand, built
from the wand driver's parameters; the driver finds it by its entry point, ``simulated``.
"""

from simulated_operator.experiments import EXPERIMENTS, make_script, needs_scene
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import (
    cuboid_face_tapping, cylinder_side_tapping, hand_dorsum_tapping, probe_sweep, ScriptError,
    TappingScript, TappingSite, Target, WaypointScript)

__all__ = [
    'EXPERIMENTS',
    'OperatorHand',
    'ScriptError',
    'TappingScript',
    'TappingSite',
    'Target',
    'WaypointScript',
    'cuboid_face_tapping',
    'cylinder_side_tapping',
    'hand_dorsum_tapping',
    'make_script',
    'needs_scene',
    'probe_sweep',
]
