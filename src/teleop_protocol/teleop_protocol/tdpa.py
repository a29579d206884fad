"""Time-domain passivity across a delayed link: each site keeps the link from creating energy.

Why: over a link of tens to hundreds of milliseconds, a force sent back to the operator is a
force on an old motion, and direct force reflection gives energy back until it oscillates. The
network representation of Artigas, Ryu, Preusche and Hirzinger (IROS 2011) treats the link as a
two-port whose energy can be booked at both ends, however it delays or drops: the energy that
enters it at one site is sent along with the data, and the other site never lets more leave the
link than has entered it at the far end. No model of the delay is needed.

Sign rule, per site and servo period ``dt``: ``link_power`` is the power the link delivers to
the site's device (operator side: the displayed force times the device's velocity; robot side:
the commanded motion against the measured contact force, ``-force · velocity``). Positive, it is
energy out of the link (``out``); negative, energy into it (``in``). A site sends its ``in``
total; the other side's ``out`` total may never pass the newest ``in`` total it has received.

The operator's side is of impedance type: its controller lowers the displayed force along the
device's velocity (a damper, never a push). The robot's side is of admittance type: its
controller moves the commanded velocity along the measured force (yielding, never pressing
harder). Yielding leaves the probe behind the operator's position: the robot's side adds a
velocity toward the commanded position (``drift_rate`` times the drift), before its controller,
so the drift is made good with the energy the link can spare and never with more (as Coelho,
Ott et al. do, arXiv 1909.01603).
"""
from dataclasses import dataclass

import numpy as np

from haptic_contract.checks import finite_number, finite_vector

__all__ = ['EnergyBooks', 'OperatorPassivity', 'RobotPassivity']


@dataclass
class EnergyBooks:
    """One end of the link: energy in and out so far (J), and the far end's ``in`` received."""

    energy_in: float = 0.0
    energy_out: float = 0.0
    far_in: float = 0.0

    def receive(self, far_in: float) -> None:
        """Take the far end's ``in`` total (J) as it arrives; an older, smaller one is kept out."""
        self.far_in = max(self.far_in, finite_number(far_in, 'far_in', minimum=0.0))

    def excess(self, link_power: float, dt: float) -> float:
        """Energy (J) by which ``link_power`` over ``dt`` would take out more than came in."""
        return self.energy_out + max(link_power, 0.0) * dt - self.far_in

    def book(self, link_power: float, dt: float) -> None:
        """Book ``link_power`` (W, > 0 out of the link) over ``dt`` (s)."""
        if link_power > 0.0:
            self.energy_out += link_power * dt
        else:
            self.energy_in -= link_power * dt


class OperatorPassivity:
    """The operator's end: the displayed force, lowered along the velocity when it must be."""

    def __init__(self) -> None:
        self.books = EnergyBooks()

    def control(self, force, velocity, dt: float) -> np.ndarray:
        """Return the force (3,) N to display for the next ``dt`` s, given the device's velocity.

        ``force`` is what arrived over the link; the result differs only by a damping along
        ``velocity`` just large enough that the link delivers no more than it received.
        """
        force = finite_vector(force, 3, 'OperatorPassivity force')
        velocity = finite_vector(velocity, 3, 'OperatorPassivity velocity')
        dt = finite_number(dt, 'OperatorPassivity dt', minimum=0.0, strict=True)
        excess = self.books.excess(float(force @ velocity), dt)
        speed_squared = float(velocity @ velocity)
        if excess > 0.0 and speed_squared > 0.0:
            damping = excess / (speed_squared * dt)
            force = force - damping * velocity
        self.books.book(float(force @ velocity), dt)
        return force


class RobotPassivity:
    """The robot's end: the commanded velocity, yielding along the contact force when it must.

    Parameters
    ----------
    drift_rate : float, 1/s
        Gain of the velocity added toward the commanded position (0: no drift compensation).
    """

    def __init__(self, drift_rate: float = 0.0) -> None:
        self.drift_rate = finite_number(drift_rate, 'RobotPassivity drift_rate', minimum=0.0)
        self.books = EnergyBooks()

    def control(self, velocity, force, dt: float, drift=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Return the velocity (3,) m/s to command for the next ``dt`` s, given the contact force.

        ``velocity`` is what arrived over the link; ``force`` the measured force of the patient
        on the probe; ``drift`` (3,) m the commanded position minus the probe's. The result moves
        along ``force`` just enough that the link delivers no more work into the patient than it
        received from the operator.
        """
        velocity = finite_vector(velocity, 3, 'RobotPassivity velocity')
        force = finite_vector(force, 3, 'RobotPassivity force')
        dt = finite_number(dt, 'RobotPassivity dt', minimum=0.0, strict=True)
        velocity = velocity + self.drift_rate * finite_vector(drift, 3, 'RobotPassivity drift')
        excess = self.books.excess(-float(force @ velocity), dt)
        force_squared = float(force @ force)
        if excess > 0.0 and force_squared > 0.0:
            velocity = velocity + excess / (force_squared * dt) * force
        self.books.book(-float(force @ velocity), dt)
        return velocity
