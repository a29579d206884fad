"""The simulated wand held by the scripted operator, built from the wand driver's parameters.

The driver finds ``simulated_wand`` through its entry point group (``setup.py`` names it
``simulated``) and never imports this package, nor the collision engine the scripted hand
needs to find the surface it taps.
"""
from typing import Callable

from haptic_util.paths import resolve_path
from haptic_wand_driver.assembly import simulated_wand_config
from haptic_wand_driver.device import HapticDevice, make_device
from haptic_wand_driver.params import WandDriverParams
from simulated_operator.experiments import make_script, needs_scene
from simulated_operator.hand import OperatorHand

__all__ = ['simulated_wand']


def simulated_wand(params: WandDriverParams,
                   announce: Callable[[str], None] = lambda line: None) -> HapticDevice:
    """Return the simulated wand with its scripted hand.

    ``announce`` hears what loading the scene says. Raises ValueError (a bad script or scene).
    """
    project = None
    if needs_scene(params.experiment):
        from collision_engine import load_scene, surface_projection  # only the experiments tap

        project = surface_projection(load_scene(
            resolve_path(params.scene_file, what='parameter scene_file'), announce=announce))
    hand = OperatorHand(make_script(params.experiment, project),
                        stiffness=params.hand_stiffness, damping=params.hand_damping)
    return make_device('simulated', config=simulated_wand_config(params), operator=hand)
