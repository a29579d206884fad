"""The wand driver's device built from its parameters, without rclpy: its node and benches call it.

``make_wand`` builds the device the parameters name (the simulated wand with its scripted hand,
a replay, or a registered backend); ``simulated_wand_config`` the simulated wand's dynamics and
limits; ``port_passivity`` and ``local_renderer`` what renders on the device.
"""
from typing import Callable

from haptic_util.paths import resolve_path
from haptic_wand_driver.device import DeviceLimits, HapticDevice, make_device
from haptic_wand_driver.experiments import make_script, needs_scene, surface_projection
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.operator import OperatorHand
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.simulated import SimulatedWandConfig

__all__ = ['local_renderer', 'make_wand', 'port_passivity', 'simulated_wand_config']


def simulated_wand_config(params: WandDriverParams) -> SimulatedWandConfig:
    """Return the simulated wand's dynamics (mass, damping, servo step) and limits."""
    return SimulatedWandConfig(
        mass=[params.device_mass] * 3, damping=[params.device_damping] * 3,
        step=1.0 / params.servo_rate,
        limits=DeviceLimits(force_limit=params.force_limit, torque_limit=params.torque_limit))


def make_wand(params: WandDriverParams,
              announce: Callable[[str], None] = lambda line: None) -> HapticDevice:
    """Return the device ``params`` name; the simulated one with its scripted hand.

    ``announce`` hears what loading the scene says. Raises ValueError (a device that is not
    available, a bad script or replay).
    """
    if params.device == 'replay':
        replay = resolve_path(params.replay_file, what='parameter replay_file')
        return make_device('replay', path=replay, loop=params.replay_loop)
    if params.device != 'simulated':
        return make_device(params.device)
    project = None
    if needs_scene(params.experiment):
        from collision_engine import load_scene  # only the scripted experiments need it

        project = surface_projection(load_scene(
            resolve_path(params.scene_file, what='parameter scene_file'), announce=announce))
    hand = OperatorHand(make_script(params.experiment, project),
                        stiffness=params.hand_stiffness, damping=params.hand_damping)
    return make_device('simulated', config=simulated_wand_config(params), operator=hand)


def port_passivity(params: WandDriverParams) -> PortPassivity:
    """Return the device port's passivity: the observer always, the controller if enabled."""
    return PortPassivity(params.passivity_max_damping if params.passivity else 0.0)


def local_renderer(params: WandDriverParams, limits: DeviceLimits,
                   passivity: PortPassivity) -> LocalRenderer:
    """Return the law a device renders contact models with at its servo rate."""
    return LocalRenderer(force_limit=limits.force_limit, torque_limit=limits.torque_limit,
                         passivity=passivity, mass=[params.device_mass] * 3,
                         contact_damping_ratio=params.contact_damping_ratio,
                         model_step_rate=params.model_step_rate)
