"""5-DOF haptic wand driver core: the device contract, a simulated wand, replay, wrench input.

Pure Python and numpy; the ROS node around it lives in ``node.py``.
"""

from haptic_contract.contact_model import ContactModel, ModelRefused
from haptic_contract.plane_law import saturate
from haptic_contract.wand import (
    PitchError, quaternion_from_roll_yaw, roll_yaw_from_quaternion, roll_yaw_jacobian)
from haptic_wand_driver.device import (
    available_devices, DeviceClosedError, DeviceLimits, DeviceUnavailableError, HapticDevice,
    LocalRenderingUnsupported, make_device, register_device, WandState, Workspace)
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.operator import OperatorHand
from haptic_wand_driver.pose_table import PoseFileError, PoseTable, read_pose_csv, write_pose_csv
from haptic_wand_driver.replay import ReplayDevice, ReplayError
from haptic_wand_driver.scripts import (
    cuboid_face_tapping, cylinder_side_tapping, hand_dorsum_tapping, ScriptError, TappingScript,
    TappingSite, Target, WaypointScript)
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
    'OperatorHand',
    'PitchError',
    'PoseFileError',
    'PoseTable',
    'ReplayDevice',
    'ReplayError',
    'ScriptError',
    'SimulatedWand',
    'SimulatedWandConfig',
    'TappingScript',
    'TappingSite',
    'Target',
    'WandState',
    'WaypointScript',
    'Workspace',
    'WrenchCommand',
    'available_devices',
    'cuboid_face_tapping',
    'cylinder_side_tapping',
    'hand_dorsum_tapping',
    'make_device',
    'quaternion_from_roll_yaw',
    'read_pose_csv',
    'register_device',
    'roll_yaw_from_quaternion',
    'roll_yaw_jacobian',
    'saturate',
    'write_pose_csv',
]
