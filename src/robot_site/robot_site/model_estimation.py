"""The remote side's online estimate of the contact, for model-mediated teleoperation.

Why: with a delayed link, a force sent back to the operator arrives too late to be rendered
stably. Model-mediated teleoperation (Mitra and Niemeyer; Xu, Cizmeci, Schuwerk and Steinbach,
2016) sends a model of the contact instead, which the operator's device renders locally at its
own rate: here a plane (point, outward normal) with a linear stiffness and damping, as the
``ContactModel`` the device already renders.

From the F/T sensor's force and the TCP's position and velocity while in contact:

- the **normal** is the direction of the measured force (the tissue pushes out), low-passed at
  ``normal_bandwidth``, from the surface's own normal where this site knows it (a depth camera,
  the phantom's mesh). Started from the contact's first force instead, at 0.5 N, the sensor's
  noise tilted the first estimate by 3-8° from the skin's (the scan's lockstep at 250 ms), and
  the plane the operator felt turned as much in one update: a jolt of up to 1.2 N sideways,
  scaled;
- along it, the force is fitted as F = k·s + c·ṡ + b by recursive least squares with
  exponential forgetting, where s is how far the TCP has gone in since the contact began, the
  sum of its steps along the normal of each moment. k and c are the tissue's stiffness and
  damping linearised where the probe is; the plane is where that line gives zero force,
  s = −b / k.

Summing steps, rather than taking s = −x·n, keeps the normal's noise out of the depth: a
normal off by δ tilts −x·n by |x|·δ, a tenth of a millimetre for a probe 10 cm from the origin,
as much as the depth changes, and the fit would read that as a softer tissue.

The sensor's low-pass filter delays the force against the motion, which would bias the damping
(by about −k / (2π·bandwidth)); passing s and ṡ through the same filter keeps the fit exact.
The covariance is capped at its initial size (scaled down whenever a variance would exceed
its prior), so a long steady press, which brings no new information, cannot wind it up into a
jump when the probe moves again.

The fit gives no plane in a contact until it knows the stiffness (one standard deviation,
from its covariance and the sensor's noise, within ``stiffness_confidence`` of it): the plane
lies at −b / k, and at a contact's start, a fraction of a millimetre in, the noise moves k
freely. Given at once, that plane lay up to 39 mm from the tissue's tangent in 40 seeded
approaches at 1 and 4 cm/s (1.4 mm once known, 13-51 ms after the touch), and 12-13 mm above
the skin in runs of the attacked session (a CI run; here with a core busy). Until then the
follower sends the surface as it sees it. A contact ends below ``contact_end_force``, under the
force that begins one, so that the noise does not end and begin contacts at the threshold, each
from a new origin of s.

A plane farther from the pressing probe than ``max_indentation`` is no estimate of a patient:
the fit starts again from its prior, as at a new contact. Fed TCP poses 50 mm off the real
ones on most samples (a stranger on the robot's network), the fit's stiffness fell to zero and
the plane ran 0.3-0.8 m out, and 99.8 m in a CI run, where the operator could not follow it
and the session stopped for good.
"""

from dataclasses import dataclass
import math
from typing import NamedTuple

import numpy as np

from haptic_contract.checks import finite_number, finite_vector
from robot_site.ft_sensor import FirstOrderLowPass

__all__ = ['ContactEstimate', 'ContactModelEstimator', 'EstimatorConfig']


@dataclass(frozen=True)
class EstimatorConfig:
    """Parameters of the contact estimator.

    Parameters
    ----------
    forgetting : float
        RLS forgetting factor per sample, in (0, 1]; memory is about 1 / (1 − forgetting)
        samples.
    contact_force : float, N
        Above this measured force a contact begins.
    contact_end_force : float, N
        Below this measured force, <= ``contact_force``, the contact ends; out of contact
        nothing is learnt.
    force_noise : float, N
        The sensor's noise, RMS per axis: how far a reading may be from the force.
    stiffness_confidence : float
        In each contact, the plane is given once the stiffness's standard deviation is within
        this fraction of it.
    sensor_bandwidth : float, Hz
        The F/T sensor's low-pass cut-off (``ForceTorqueSensorConfig.bandwidth``).
    normal_bandwidth : float, Hz
        Cut-off of the low-pass on the force's direction, the normal.
    initial_stiffness : float, N/m
    initial_damping : float, N·s/m
        The guesses before any contact.
    max_indentation : float, m
        The farthest the plane may lie from the TCP in contact: deeper than a probe presses
        any tissue.
    stiffness_spread, damping_spread, offset_spread : float
        How far (N/m, N·s/m, N; one standard deviation) the truth may lie from the guesses:
        the initial covariance, and its cap.
    """

    forgetting: float = 0.999
    contact_force: float = 0.5
    contact_end_force: float = 0.25
    force_noise: float = 0.05
    stiffness_confidence: float = 0.2
    sensor_bandwidth: float = 200.0
    normal_bandwidth: float = 2.0
    initial_stiffness: float = 500.0
    initial_damping: float = 5.0
    max_indentation: float = 0.05
    stiffness_spread: float = 1e4
    damping_spread: float = 100.0
    offset_spread: float = 100.0

    def __post_init__(self):
        finite_number(self.forgetting, 'EstimatorConfig.forgetting', minimum=0.0, strict=True,
                      maximum=1.0)
        for name in ('contact_force', 'force_noise', 'initial_stiffness', 'initial_damping'):
            finite_number(getattr(self, name), f'EstimatorConfig.{name}', minimum=0.0)
        finite_number(self.contact_end_force, 'EstimatorConfig.contact_end_force', minimum=0.0,
                      maximum=self.contact_force)
        for name in ('sensor_bandwidth', 'normal_bandwidth', 'max_indentation', 'stiffness_spread',
                     'damping_spread', 'offset_spread', 'stiffness_confidence'):
            finite_number(getattr(self, name), f'EstimatorConfig.{name}', minimum=0.0,
                          strict=True)


class ContactEstimate(NamedTuple):
    """A plane for the operator's device to render.

    Attributes
    ----------
    point : (3,) float, m
        A point of the plane: the TCP's position moved along the normal onto it.
    normal : (3,) float
        Unit, outward (from the patient toward the probe).
    stiffness : float, N/m
    damping : float, N·s/m
    """

    point: np.ndarray
    normal: np.ndarray
    stiffness: float
    damping: float


class ContactModelEstimator:
    """Learns the contact plane and its gains from the force and the motion, sample by sample.

    Parameters
    ----------
    config : EstimatorConfig
    """

    def __init__(self, config: EstimatorConfig = EstimatorConfig()) -> None:
        self.config = config
        self._prior = np.diag(np.square(
            [config.stiffness_spread, config.damping_spread, config.offset_spread]))
        self._restart()
        self._last_time: float | None = None

    def _restart(self) -> None:
        """Forget what was learnt: the prior, out of contact."""
        config = self.config
        self._parameters = np.array([config.initial_stiffness, config.initial_damping, 0.0])
        self._covariance = self._prior.copy()
        self._force: FirstOrderLowPass | None = None  # None out of contact
        self._stiffness_known = False  # in this contact
        self._motion: FirstOrderLowPass | None = None
        self._depth = 0.0  # s, m
        self._last_position = np.zeros(3)

    def update(self, time: float, force, position, velocity,
               surface_normal=None) -> ContactEstimate | None:
        """Learn from one sample; return the estimate, or None (no contact, or no plane yet).

        In a contact, the first plane comes once the fit knows the stiffness.

        Parameters
        ----------
        time : float, s
        force : (3,) float, N
            The measured force on the probe.
        position, velocity : (3,) float, m and m/s
            The TCP's.
        surface_normal : callable or None
            Returns the surface's outward unit normal (3,) under the TCP, where the normal's
            filter starts at a contact's first sample; None: from that sample's force.
        """
        time = finite_number(time, 'ContactModelEstimator.update time')
        force = finite_vector(force, 3, 'ContactModelEstimator.update force')
        position = finite_vector(position, 3, 'ContactModelEstimator.update position')
        velocity = finite_vector(velocity, 3, 'ContactModelEstimator.update velocity')
        elapsed = 0.0 if self._last_time is None else time - self._last_time
        if elapsed < 0.0:
            raise ValueError(f'ContactModelEstimator.update: time {time!r} s is before the last '
                             f'sample ({self._last_time!r} s); the clock must not go back')
        self._last_time = time
        in_contact = self._force is not None
        if np.linalg.norm(force) < (self.config.contact_end_force if in_contact
                                    else self.config.contact_force):
            self._force = self._motion = None  # the next contact starts afresh from its force
            return None
        if not in_contact:
            self._force = FirstOrderLowPass(self.config.normal_bandwidth,
                                            _first_normal(force, surface_normal))
            self._depth, self._last_position = 0.0, position
            self._stiffness_known = False
        average = self._force.update(elapsed, force)
        normal = average / np.linalg.norm(average)
        self._depth -= (position - self._last_position) @ normal
        self._last_position = position
        motion = np.array([self._depth, -velocity @ normal])  # s and ṡ
        if self._motion is None:
            self._motion = FirstOrderLowPass(self.config.sensor_bandwidth, motion)
        depth, depth_rate = self._motion.update(elapsed, motion)
        self._learn(np.array([depth, depth_rate, 1.0]), float(force @ normal))
        self._stiffness_known = self._stiffness_known or self._knows_stiffness()
        return self._estimate(position, normal) if self._stiffness_known else None

    def _knows_stiffness(self) -> bool:
        """Whether the stiffness's standard deviation is within ``stiffness_confidence`` of it.

        RLS's covariance is the parameters' for a unit noise: scaled by the sensor's.
        """
        spread = self.config.force_noise * math.sqrt(self._covariance[0, 0])
        return spread <= self.config.stiffness_confidence * self._parameters[0]

    def _learn(self, regressor: np.ndarray, measured: float) -> None:
        """One step of recursive least squares with forgetting; the covariance stays capped."""
        forgetting = self.config.forgetting
        spread = self._covariance @ regressor
        gain = spread / (forgetting + regressor @ spread)
        self._parameters = self._parameters + gain * (measured - regressor @ self._parameters)
        covariance = (self._covariance - np.outer(gain, spread)) / forgetting
        excess = np.max(np.diag(covariance) / np.diag(self._prior))
        self._covariance = covariance / max(excess, 1.0)

    def _estimate(self, position: np.ndarray, normal: np.ndarray) -> ContactEstimate | None:
        """Return the plane through zero force, the TCP moved out onto it along the normal.

        None, and the fit restarted, when that plane lies too far from the TCP to be the skin.
        """
        stiffness, damping, offset = self._parameters
        stiffness, damping = max(stiffness, 0.0), max(damping, 0.0)
        surface_depth = -offset / stiffness if stiffness > 0.0 else self._depth
        indentation = self._depth - surface_depth
        if abs(indentation) > self.config.max_indentation:
            self._restart()
            return None
        point = position + indentation * normal
        return ContactEstimate(point, normal, float(stiffness), float(damping))


def _first_normal(force: np.ndarray, surface_normal) -> np.ndarray:
    """Return where the normal's filter starts: the force turned onto the surface's normal.

    The force itself when no normal is known, or when the surface's faces away from it.
    """
    if surface_normal is None:
        return force
    normal = finite_vector(surface_normal(), 3, 'ContactModelEstimator surface normal')
    along = float(force @ normal)
    return normal * along if along > 0.0 else force
