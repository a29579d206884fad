"""The wand driver's device built from its parameters, without rclpy: its node and benches call it.

``make_wand`` builds the device the parameters name (a replay, one an installed package assembles,
or a registered backend); ``simulated_wand_config`` the simulated wand's dynamics and limits;
``port_passivity`` and ``local_renderer`` what renders on the device.

A package that builds a device from these parameters names its function in the entry point group
``WAND_ASSEMBLIES``, as pluginlib would a plugin, and the driver finds it there without importing
that package: ``simulated_operator`` so assembles the simulated wand with its scripted hand (and
the scene the hand taps), which a driver of real hardware never needs.
"""
from importlib.metadata import entry_points
from typing import Callable

from haptic_util.paths import resolve_path
from haptic_wand_driver.device import (DeviceLimits, DeviceUnavailableError, HapticDevice,
                                       make_device)
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.simulated import SimulatedWandConfig

__all__ = ['WAND_ASSEMBLIES', 'local_renderer', 'make_wand', 'port_passivity',
           'simulated_wand_config']

WAND_ASSEMBLIES = 'haptic_wand_driver.wands'
"""Entry points ``<device> = <module>:<function>``; ``function(params, announce)`` builds it."""


def simulated_wand_config(params: WandDriverParams) -> SimulatedWandConfig:
    """Return the simulated wand's dynamics (mass, damping, servo step) and limits."""
    return SimulatedWandConfig(
        mass=[params.device_mass] * 3, damping=[params.device_damping] * 3,
        step=1.0 / params.servo_rate,
        limits=DeviceLimits(force_limit=params.force_limit, torque_limit=params.torque_limit))


def make_wand(params: WandDriverParams,
              announce: Callable[[str], None] = lambda line: None) -> HapticDevice:
    """Return the device ``params`` name; the simulated one from its installed assembly.

    ``announce`` hears what building it says (loading a scene). Raises ValueError (a device that
    is not available, a bad script or replay).
    """
    if params.device == 'replay':
        replay = resolve_path(params.replay_file, what='parameter replay_file')
        return make_device('replay', path=replay, loop=params.replay_loop)
    assemblies = entry_points(group=WAND_ASSEMBLIES, name=params.device)
    if len(assemblies) > 1:
        raise DeviceUnavailableError(
            f'device {params.device!r} is assembled by more than one installed package: '
            f'{", ".join(sorted(entry.value for entry in assemblies))}')
    if assemblies:
        (assembly,) = assemblies
        return assembly.load()(params, announce)
    if params.device == 'simulated':
        raise DeviceUnavailableError(
            "device 'simulated' is moved by the simulated operator's hand: install the "
            f'simulated_operator package, which assembles it (entry point group '
            f'{WAND_ASSEMBLIES})')
    try:
        return make_device(params.device)
    except DeviceUnavailableError as error:
        raise DeviceUnavailableError(f'{error} Or its package names a function building it from '
                                     f'these parameters in the entry point group '
                                     f'{WAND_ASSEMBLIES}.') from None


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
