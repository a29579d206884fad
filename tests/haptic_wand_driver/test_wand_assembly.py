"""The driver's device from its parameters: the simulated wand from the package that holds it.

A driver of real hardware needs neither the scripted operator nor the collision engine its
scripts tap; the simulated wand is found by entry point, as pluginlib finds a plugin.
"""
from importlib.metadata import EntryPoint, EntryPoints

import pytest
from test_manifests import imported

from haptic_wand_driver import assembly
from haptic_wand_driver.device import DeviceUnavailableError
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.simulated import SimulatedWand


def installed(*entries: EntryPoint):
    """Return an ``entry_points`` that sees only ``entries``."""
    def entry_points(*, group, name):
        return EntryPoints(e for e in entries if e.group == group and e.name == name)
    return entry_points


def quanser(params, announce):
    """A hardware backend's assembly, as a package would name it."""
    return ('quanser', params.force_limit)


def test_the_driver_imports_neither_the_simulated_operator_nor_the_collision_engine():
    needed = imported('haptic_wand_driver')
    assert {'numpy', 'rclpy', 'haptic_contract'} <= needed  # the scan read the driver's code
    assert needed & {'simulated_operator', 'collision_engine'} == set()


def test_the_simulated_wand_is_the_installed_operator_s_held_by_its_scripted_hand():
    wand = assembly.make_wand(WandDriverParams())  # the cuboid tapping script, on its scene
    assert isinstance(wand, SimulatedWand)
    start = wand.read(0.0).position
    assert start.tolist() == [0.0, 0.0, 0.0]
    assert wand.read(2.0).position[2] < -0.02  # the hand took the free wand down to the cuboid


def test_without_the_operator_installed_the_simulated_device_says_what_to_install(monkeypatch):
    monkeypatch.setattr(assembly, 'entry_points', installed())
    with pytest.raises(DeviceUnavailableError, match='install the simulated_operator package'):
        assembly.make_wand(WandDriverParams())


def test_a_package_assembles_its_device_from_the_driver_s_parameters(monkeypatch):
    monkeypatch.setattr(assembly, 'entry_points', installed(
        EntryPoint('quanser', f'{__name__}:quanser', assembly.WAND_ASSEMBLIES)))
    assert assembly.make_wand(WandDriverParams(device='quanser', force_limit=4.0)) == (
        'quanser', 4.0)


def test_a_device_two_packages_assemble_is_refused_naming_both(monkeypatch):
    monkeypatch.setattr(assembly, 'entry_points', installed(*(
        EntryPoint('quanser', f'{package}:quanser', assembly.WAND_ASSEMBLIES)
        for package in ('one', 'two'))))
    with pytest.raises(DeviceUnavailableError, match='more than one.*one:quanser, two:quanser'):
        assembly.make_wand(WandDriverParams(device='quanser'))


def test_a_device_nothing_provides_is_refused_naming_what_is_available(monkeypatch):
    monkeypatch.setattr(assembly, 'entry_points', installed())
    with pytest.raises(DeviceUnavailableError, match="'quanser' is not available; available: "
                       r"replay, simulated\..* entry point group haptic_wand_driver\.wands\."):
        assembly.make_wand(WandDriverParams(device='quanser'))
