"""The map between the operator's wand and the remote probe: scaling, and a clutch.

Why: the sonographer's wand moves in a workspace of its own, and a robot may need finer or
coarser motion than the hand, and less force on the hand than on the patient. The robot's target
is ``anchor_robot + position_scale · (wand − anchor_wand)``; a force felt is ``force_scale`` ×
the patient's. The axes of the two frames are taken as aligned.

The clutch lets the operator re-centre the wand without moving the robot: while it is engaged
the target stays where it was, and on release the anchors move so that the target goes on from
there, without a jump.
"""
import numpy as np

from haptic_contract.checks import finite_number, finite_vector

__all__ = ['WorkspaceMap']


class WorkspaceMap:
    """Wand ↔ robot positions, forces and gains, with a clutch.

    Parameters
    ----------
    position_scale : float
        Robot motion per wand motion (m/m).
    force_scale : float
        Force felt per patient force (N/N).
    wand_start, robot_start : (3,) float, m
        The first anchors: where the wand and the robot's TCP are when the session starts.
    """

    def __init__(self, position_scale: float, force_scale: float, wand_start,
                 robot_start) -> None:
        self.position_scale = finite_number(position_scale, 'position_scale', minimum=0.0,
                                            strict=True)
        self.force_scale = finite_number(force_scale, 'force_scale', minimum=0.0, strict=True)
        self._wand_anchor = finite_vector(wand_start, 3, 'wand_start')
        self._robot_anchor = finite_vector(robot_start, 3, 'robot_start')
        self._held: np.ndarray | None = None  # the robot's target while the clutch is engaged

    @property
    def clutched(self) -> bool:
        """Whether the clutch is engaged (the wand moves the robot no more)."""
        return self._held is not None

    def to_robot(self, wand) -> np.ndarray:
        """Return the robot's target (3,) m for the wand at ``wand`` (3,) m."""
        if self._held is not None:
            return self._held.copy()
        return self._robot_anchor + self.position_scale * (np.asarray(wand) - self._wand_anchor)

    def to_wand(self, point) -> np.ndarray:
        """Return where (3,) m the robot's ``point`` (3,) m lies for the wand."""
        return self._wand_anchor + (np.asarray(point) - self._robot_anchor) / self.position_scale

    def velocity_to_robot(self, velocity) -> np.ndarray:
        """Return the robot's velocity (3,) m/s for the wand's; zero while clutched."""
        if self._held is not None:
            return np.zeros(3)
        return self.position_scale * np.asarray(velocity, dtype=np.float64)

    def felt_gain(self, patient_gain: float) -> float:
        """Return the gain on the wand (N/m or N·s/m) that feels as ``patient_gain`` at the robot.

        A wand step δ moves the robot by s·δ, whose force f·k·s·δ the hand feels scaled.
        """
        return self.force_scale * self.position_scale * patient_gain

    def engage(self, wand) -> None:
        """Engage the clutch with the wand at ``wand`` (3,) m: the target stays where it is."""
        if self._held is None:
            self._held = self.to_robot(wand)

    def release(self, wand) -> None:
        """Release the clutch with the wand at ``wand``: the target goes on from where it is."""
        if self._held is not None:
            self._robot_anchor, self._held = self._held, None
            self._wand_anchor = finite_vector(wand, 3, 'wand')
