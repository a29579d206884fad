"""The patient's tissue: a Hunt–Crossley contact along the surface normal.

Why: soft tissue stiffens as it is pressed and loses energy as it moves, and a probe force that
feels right must come from a law with both. Hunt–Crossley (K. H. Hunt and F. R. E. Crossley,
"Coefficient of restitution interpreted as damping in vibroimpact", J. Appl. Mech. 42(2), 1975)
gives both with three numbers, and is the common haptic stand-in for tissue::

    F = k·xⁿ + λ·xⁿ·ẋ        (x: indentation depth, ẋ its rate; F >= 0, never pulling)

The damping scales with xⁿ, so the force starts at zero on touching and has no jump.

Defaults (``ABDOMEN``), chosen in the ranges of docs the project gathered
(``/work/shared/telerobotics.md``, "Ultrasound contact"):

- probe forces are 5–20 N in typical exams, up to 34.5 N abdominal (Sensors 25(11):3415, 2025),
  at in vivo abdominal indentations up to about 30 mm (Remus et al., Front. Bioeng. 2024);
- Hunt–Crossley with n ≈ 1.2–1.5, k and λ chosen so that 10 N comes at 15–20 mm.

So n = 1.3 and k = 2000 N/m^1.3: 10 N at 17 mm and 20 N at 29 mm. λ = 1.5·α·k with α = 0.5 s/m
(Hunt and Crossley's relation of λ to the restitution, e ≈ 1 − α·v): a plausible, strongly
damped value, not a measurement; at scanning speeds of cm/s its force is a few per cent of the
spring's.

The geometry is separate: a ``Surface`` says how deep a point is and along which outward normal,
either a plane (``PlaneSurface``) or the collision engine's patient phantom (``SceneSurface``).
"""

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from haptic_contract.checks import finite_number, finite_vector, unit_vector

__all__ = ['ABDOMEN', 'HuntCrossley', 'PlaneSurface', 'SceneSurface', 'Surface', 'Tissue']


@dataclass(frozen=True)
class HuntCrossley:
    """The Hunt–Crossley law F = k·xⁿ + λ·xⁿ·ẋ, clipped at zero.

    Parameters
    ----------
    stiffness : float, N/mⁿ
        k, > 0.
    exponent : float
        n, >= 1.
    damping : float, N·s/m⁽ⁿ⁺¹⁾
        λ, >= 0.
    """

    stiffness: float
    exponent: float
    damping: float

    def __post_init__(self):
        finite_number(self.stiffness, 'HuntCrossley.stiffness', minimum=0.0, strict=True)
        finite_number(self.exponent, 'HuntCrossley.exponent', minimum=1.0)
        finite_number(self.damping, 'HuntCrossley.damping', minimum=0.0)

    def normal_force(self, depth: float, depth_rate: float) -> float:
        """Return the force (N, >= 0) at ``depth`` m (> 0 inside), going in at ``depth_rate``."""
        if depth <= 0.0:
            return 0.0
        spring = depth ** self.exponent
        return max(0.0, spring * (self.stiffness + self.damping * depth_rate))

    def static_depth(self, force: float) -> float:
        """Return the depth (m) at which the tissue at rest pushes back with ``force`` N (>= 0)."""
        force = finite_number(force, 'HuntCrossley.static_depth force', minimum=0.0)
        return (force / self.stiffness) ** (1.0 / self.exponent)

    def tangent_stiffness(self, depth: float) -> float:
        """Return dF/dx at rest at ``depth`` m: n·k·xⁿ⁻¹, N/m (the linearised stiffness)."""
        if depth <= 0.0:
            return 0.0
        return self.exponent * self.stiffness * depth ** (self.exponent - 1.0)

    def tangent_damping(self, depth: float) -> float:
        """Return dF/dẋ at ``depth`` m: λ·xⁿ, N·s/m (the linearised damping)."""
        return self.damping * max(depth, 0.0) ** self.exponent


ABDOMEN = HuntCrossley(stiffness=2000.0, exponent=1.3, damping=1500.0)
"""The abdomen's tissue: 10 N at 17 mm, 20 N at 29 mm (see the module's docstring)."""


class Surface(Protocol):
    """Where a point is against the patient's skin."""

    def penetration(self, position: np.ndarray) -> tuple[float, np.ndarray]:
        """Return the depth (m, > 0 inside) of ``position`` (3,) and the unit outward normal."""

    def penetration_floats(self, position) -> tuple[float, tuple]:
        """Return ``penetration`` from three floats, the normal as floats: the robot's substeps."""


class PlaneSurface:
    """A flat skin through ``point`` (3,) m with the outward ``normal`` (3,)."""

    def __init__(self, point, normal) -> None:
        self.point = finite_vector(point, 3, 'PlaneSurface.point')
        self.normal = unit_vector(normal, 3, 'PlaneSurface.normal')
        self._normal_floats = tuple(self.normal.tolist())

    def penetration(self, position: np.ndarray) -> tuple[float, np.ndarray]:
        """Return the depth below the plane (m) and its normal."""
        return float(np.dot(self.point - position, self.normal)), self.normal

    def penetration_floats(self, position) -> tuple[float, tuple]:
        """Return the depth below the plane (m) and its normal as floats."""
        return self.penetration(position)[0], self._normal_floats


class SceneSurface:
    """The skin of a collision-engine scene (e.g. ``scenes/phantom.yaml``): signed distance.

    Parameters
    ----------
    scene : collision_engine.Scene
        Any object whose ``query(point)`` returns a signed ``distance`` (negative inside) and a
        unit outward ``normal``, both also in its packed ``row`` (distance at 0, normal at 4:7).
    """

    def __init__(self, scene) -> None:
        self._scene = scene
        self._query = scene.query

    def penetration(self, position: np.ndarray) -> tuple[float, np.ndarray]:
        """Return the depth inside the nearest object (m) and its outward normal there."""
        depth, normal = self.penetration_floats(position)
        return depth, np.array(normal)

    def penetration_floats(self, position) -> tuple[float, tuple]:
        """Return the depth inside the nearest object (m) and its outward normal, as floats.

        From the query's packed row: its ``normal`` would be an array made for three floats.
        """
        row = self._query(position).row
        return -row[0], (row[4], row[5], row[6])


_NO_FORCE = (0.0, 0.0, 0.0)


class Tissue:
    """The force of the patient on the probe's tip: ``law`` along the ``surface``'s normal.

    An ``impedance_robot.Environment``: call it with the tip's position (m) and velocity (m/s),
    or ``force_floats`` with floats.
    """

    def __init__(self, law: HuntCrossley = ABDOMEN, surface: Surface | None = None) -> None:
        self.law = law
        self.surface = surface if surface is not None else PlaneSurface(np.zeros(3), [0, 0, 1])

    def __call__(self, position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """Return the force (3,) N on the tip, along the outward normal, zero outside."""
        return np.array(self.force_floats(position, velocity))

    def force_floats(self, position, velocity) -> tuple:
        """Return the force (N) on the tip as three floats, from three floats of each argument.

        The robot calls this twice a 1 kHz tick: numpy costs more than three floats' arithmetic.
        """
        depth, (nx, ny, nz) = self.surface.penetration_floats(position)
        if depth <= 0.0:
            return _NO_FORCE
        vx, vy, vz = velocity
        # A plain sum: np.dot (OpenBLAS) fuses the multiply-adds, so it may differ in the last bit.
        magnitude = self.law.normal_force(depth, -(vx * nx + vy * ny + vz * nz))
        return magnitude * nx, magnitude * ny, magnitude * nz
