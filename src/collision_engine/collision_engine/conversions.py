"""Messages ↔ the collision core: tip position in, CollisionState out."""
import math

from geometry_msgs.msg import PoseStamped

from haptic_msgs.msg import CollisionState

__all__ = ['InvalidPose', 'tip_position', 'fill_state', 'fill_invalid_state']

UNIT_QUATERNION_TOLERANCE = 1e-3  # |q| may differ from 1 by this much (float32 round trips)


class InvalidPose(ValueError):
    """A pose the engine refuses; the message names the field and what is wrong.

    ``kind`` is a fixed short text of the fault, for counting.
    """

    def __init__(self, kind: str, message: str) -> None:
        super().__init__(message)
        self.kind = kind


def tip_position(msg: PoseStamped, frame_id: str) -> tuple:
    """Return the tip position (x, y, z) [m] of a pose in the scene frame, or raise InvalidPose."""
    if msg.header.frame_id != frame_id:
        raise InvalidPose('pose in an unknown frame',
                          f'pose.header.frame_id is {msg.header.frame_id!r}, not the scene '
                          f'frame {frame_id!r} (no transform is looked up)')
    p, q = msg.pose.position, msg.pose.orientation
    for name, value in (('x', p.x), ('y', p.y), ('z', p.z)):
        if not math.isfinite(value):
            raise InvalidPose('non-finite position', f'pose.position.{name} is {value}')
    for name, value in (('x', q.x), ('y', q.y), ('z', q.z), ('w', q.w)):
        if not math.isfinite(value):
            raise InvalidPose('non-finite orientation', f'pose.orientation.{name} is {value}')
    norm = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if abs(norm - 1.0) > UNIT_QUATERNION_TOLERANCE:
        raise InvalidPose('non-unit quaternion',
                          f'pose.orientation is not a unit quaternion (|q| = {norm:.6g})')
    return (p.x, p.y, p.z)


def fill_state(state: CollisionState, header, result, compute_time: float,
               disagreements: int) -> CollisionState:
    """Write one query result into a (reused) CollisionState message."""
    state.header = header
    state.object = result.object or ''  # an empty scene has no nearest object
    state.status = result.status
    state.distance = result.distance
    state.in_collision = result.in_collision
    _set_xyz(state.closest_point, result.point)
    _set_xyz(state.normal, result.normal)
    _set_xyz(state.penetration, result.penetration)
    _set_xyz(state.tip, result.tip)
    state.gjk_iterations = result.iterations
    state.cross_validated = result.cross_validated
    state.fcl_distance = result.fcl_distance
    state.fcl_discrepancy = result.fcl_discrepancy
    state.fcl_disagreements = disagreements
    state.compute_time = compute_time
    return state


def fill_invalid_state(state: CollisionState, header, disagreements: int) -> CollisionState:
    """Mark a state invalid: the renderer then sends zero force."""
    nan = math.nan
    state.header = header
    state.object = ''
    state.status = CollisionState.STATUS_INVALID_INPUT
    state.distance = nan
    state.in_collision = False
    for vector in (state.closest_point, state.normal, state.penetration, state.tip):
        _set_xyz(vector, (nan, nan, nan))
    state.gjk_iterations = 0
    state.cross_validated = False
    state.fcl_distance = nan
    state.fcl_discrepancy = nan
    state.fcl_disagreements = disagreements
    state.compute_time = 0.0
    return state


def _set_xyz(vector, values) -> None:
    vector.x, vector.y, vector.z = float(values[0]), float(values[1]), float(values[2])
