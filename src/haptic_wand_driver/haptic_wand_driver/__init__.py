"""5-DOF haptic wand driver core: the device contract, a simulated wand, replay, wrench input.

Pure Python and numpy; the ROS node around it lives in ``node.py``. The operator who holds the
simulated wand (the scripts, the hand) is the ``simulated_operator`` package.
"""

from haptic_contract.contact_model import ContactModel, ModelRefused
from haptic_contract.plane_law import saturate
from haptic_contract.wand import (
    PitchError, quaternion_from_roll_yaw, roll_yaw_from_quaternion, roll_yaw_jacobian)
from haptic_wand_driver.device import (
    available_devices, DeviceClosedError, DeviceLimits, DeviceUnavailableError, HapticDevice,
    LocalRenderingUnsupported, make_device, register_device, WandState, Workspace)
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.pose_table import PoseFileError, PoseTable, read_pose_csv, write_pose_csv
from haptic_wand_driver.replay import ReplayDevice, ReplayError
from haptic_wand_driver.simulated import SimulatedWand, SimulatedWandConfig
from haptic_wand_driver.wrench_input import WrenchCommand

__all__ = [
    'ContactModel',
    'DeviceClosedError',
    'DeviceLimits',
    'DeviceUnavailableError',
    'HapticDevice',
    'LocalRenderer',
    'LocalRenderingUnsupported',
    'ModelRefused',
    'PitchError',
    'PoseFileError',
    'PoseTable',
    'ReplayDevice',
    'ReplayError',
    'SimulatedWand',
    'SimulatedWandConfig',
    'WandState',
    'Workspace',
    'WrenchCommand',
    'available_devices',
    'make_device',
    'quaternion_from_roll_yaw',
    'read_pose_csv',
    'register_device',
    'roll_yaw_from_quaternion',
    'roll_yaw_jacobian',
    'saturate',
    'write_pose_csv',
]
