"""The robot's TCP as the commanding node takes it: only poses the robot can have.

Why: the TCP pose crosses the robot's network (a real arm's driver publishes it), and the
follower learns the patient from it. A stranger there published poses 50 mm below the real ones
at 2 kHz, beside them: the follower's depth jumped 50 mm and its velocity by 100 m/s from one
tick to the next, the contact estimate ran off (to 99.8 m in a CI run), the operator's commands
followed it out of the workspace, and the session stopped for good. A pose outside the robot's
workspace, or farther from the last one taken than the robot's top speed covers in the time
between, is refused. That reach grows with the time since the last pose taken, so a gate held
by a stream that then stops lets the true poses in again.
"""
import numpy as np

from haptic_contract.checks import floats3, within_box
from haptic_contract.teleop import Refusal

__all__ = ['TcpGate', 'TCP_TOLERANCE']

TCP_TOLERANCE = 2e-3  # [m] a pose's noise, and a step taken between two arrivals at once


class TcpGate:
    """Takes the TCP's positions one by one, refusing those the robot cannot have reached.

    Parameters
    ----------
    workspace_lower, workspace_upper : (3,) float, m
        The box the robot's TCP stays in.
    max_speed : float, m/s
        The TCP's top speed.
    """

    def __init__(self, workspace_lower, workspace_upper, max_speed: float) -> None:
        self.bound(workspace_lower, workspace_upper, max_speed)
        self.position: np.ndarray | None = None  # [m] the last taken
        self.velocity = np.zeros(3)  # [m/s] between the last two taken
        self.time = -np.inf  # [s] when the last was taken

    def bound(self, workspace_lower, workspace_upper, max_speed: float) -> None:
        """Check the poses to come against these limits: the robot's latest report."""
        self._lower, self._upper = floats3(workspace_lower), floats3(workspace_upper)
        self._max_speed = float(max_speed)

    def take(self, now: float, position) -> Refusal | None:
        """Take ``position`` (3,) m arrived at ``now`` (s); return None, or why it was refused."""
        position = np.asarray(position, dtype=np.float64)
        if not np.all(np.isfinite(position)):
            return Refusal('TCP not finite', str(position))
        if not within_box(position, self._lower, self._upper, TCP_TOLERANCE):
            return Refusal('TCP outside the workspace', _millimetres(position))
        if self.position is not None:
            elapsed = max(now - self.time, 0.0)
            jump = float(np.linalg.norm(position - self.position))
            if jump > self._max_speed * elapsed + TCP_TOLERANCE:
                return Refusal('TCP faster than the robot',
                               f'{jump * 1e3:.1f} mm in {elapsed * 1e3:.2f} ms')
            if elapsed > 0.0:
                self.velocity = (position - self.position) / elapsed
        self.position, self.time = position, now
        return None


def _millimetres(position: np.ndarray) -> str:
    return '(' + ', '.join(f'{x * 1e3:.1f}' for x in position) + ') mm'
