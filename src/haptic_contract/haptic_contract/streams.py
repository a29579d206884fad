"""The wand's 1 kHz streams (pose, twist, wrench) as the codec's flat tuples, read by name.

A wand sample is a stamped pose (``wand/pose``) and a stamped twist (``wand/twist``) of one
stamp; the answer to it a stamped wrench (``wand/wrench``). A device rendering models itself also
says how far out it renders their planes (``wand/model_shift``, a stamped vector). Their readers
take the stamp, the frame and the vectors through the slices here.
"""
from geometry_msgs.msg import PoseStamped, TwistStamped, Vector3Stamped, WrenchStamped

from haptic_contract.fields import span, vector
from haptic_util.cdr import MessageCodec

__all__ = ['FRAME', 'POSE', 'POSE_ORIENTATION', 'POSE_POSITION', 'TWIST', 'TWIST_ANGULAR',
           'TWIST_LINEAR', 'VECTOR', 'VECTOR_VALUE', 'WRENCH', 'WRENCH_FORCE', 'WRENCH_TORQUE',
           'frame', 'header', 'stamp_ns']

POSE = MessageCodec(PoseStamped)
TWIST = MessageCodec(TwistStamped)
WRENCH = MessageCodec(WrenchStamped)
VECTOR = MessageCodec(Vector3Stamped)
_SEC = POSE.index('header.stamp.sec')
_NANOSEC = POSE.index('header.stamp.nanosec')
FRAME = POSE.index('header.frame_id')
_HEADER = span(POSE, 'header.stamp.sec', 'header.frame_id')
POSE_POSITION = vector(POSE, 'pose.position')
POSE_ORIENTATION = vector(POSE, 'pose.orientation', 'w')
TWIST_LINEAR = vector(TWIST, 'twist.linear')
TWIST_ANGULAR = vector(TWIST, 'twist.angular')
WRENCH_FORCE = vector(WRENCH, 'wrench.force')
WRENCH_TORQUE = vector(WRENCH, 'wrench.torque')
VECTOR_VALUE = vector(VECTOR, 'vector')
_SECOND = 1_000_000_000  # every stamped message begins with its header: these read them all


def stamp_ns(fields) -> int:
    """Return the header's stamp of a stamped message's fields, in integer nanoseconds."""
    return fields[_SEC] * _SECOND + fields[_NANOSEC]


def header(fields) -> tuple:
    """Return the header of a stamped message's fields: (sec, nanosec, frame_id)."""
    return tuple(fields[_HEADER])


def frame(fields) -> str:
    """Return the header's frame of a stamped message's fields."""
    return fields[FRAME]
