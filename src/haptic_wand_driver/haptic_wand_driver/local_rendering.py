"""The device-side law: the latest contact model rendered at the servo rate, passive, saturated.

A backend with a servo loop of its own (a Force Dimension or Quanser device, or the simulated
wand's substeps) calls ``LocalRenderer.wrench`` every servo period with the device's current
state; the driver hands it each new model as it arrives (``take``). What it renders is zero
whenever the model is missing, expired (a servo period that would end after its deadline, on the
device's clock, renders nothing) or left behind (the tip beyond its ``valid_radius``): never a
stale force. The port's passivity controller runs here,
at the servo rate, on the force the model gives, and the result is saturated to the device's and
the model's force limits.

Contact damping: a wall of stiffness K on the device's mass m rings at sqrt(K/m) and, with only
the material's damping (the paper's 0.8 N·s/m), bounces the tool off it on every tap however
exactly it is rendered. Only the device can afford to damp that: it knows m, and at its servo rate
T a damper stays stable up to about m/T (0.15 kg at 4 kHz: 600 N·s/m), while over the ROS 2 loop
(T = 1 ms plus the round trip) it would oscillate itself. So, along each plane's normal while it
pushes, it adds ``contact_damping_ratio`` × 2 sqrt(K_n m_n) (1: critical), capped at
``MAX_DAMPING_PER_MASS`` × m_n / T, and never pulling: taps that stay in contact, as on a real
rigid surface, and energy only ever taken out. It is taken off the plane's force already saturated
to the limit, so a wall pressed past its force limit still takes energy out on the way back.

Passive at any tick rate: the first servo period that renders a model's planes moves them out as
far as the port's books require (``port_passivity.bounded_shift``), and keeps that shift for the
model's life. A model that comes after a late tick, the one before expired and the hand in
deeper, then gives back no more than the hand put in.

Smooth at any update rate, with ``model_step_rate`` > 0 (``model_easing``): a new model's planes
start as stiff and as damped as the last period's and where they push as much, and ease to the
model at that many N/s of push, held every period to the port's bound. 0 switches at once, as above
(the baseline).

A model renders from the servo period that holds its ``since`` (the device's clock when it
arrived), and what was held before renders the periods until then: so a device that runs its
periods after the fact (the simulated wand, on each read) switches where a real one would,
without being advanced at every arrival. One ``take`` at a time: a device must have run the
period of the last ``since`` before the next ``take``, or that model is never rendered.

Thread safety: ``take`` swaps one tuple, which a servo thread reads whole; the passivity books and
``bound`` are the servo thread's alone.

``packed`` is the same as floats for the simulated wand's compiled servo loop (``servo_loop``,
run in the thread that calls ``take``: the packing is not atomic), rewritten by every ``take``,
``take_wrench`` or ``clear``: row 0 the law from its ``since`` on, row 1 the one before. A row:
the force and torque limits, the contact damping ratio, the mass (3); the mode (``MODE_*``), the
deadline, the model's force limit, valid radius and tip (3), the held wrench (6), the plane
count, the damping cap per mass and period (``MAX_DAMPING_PER_MASS``), ``since``, the take's
number, the model step rate; from ``PLANES_AT`` the planes, ``PLANE_SIZE`` floats each (point,
normal, stiffness, damping, tool point). ``bound`` is the planes' shift (m), the number of the take
it was set for, the spring push the planes rendered in the last period (N; 0 when none), the
factor on their stiffnesses and the sum of those scaled (N/m; 0 when none), the damping added to
each plane's (N·s/m) and the sum of their dampings with it (N·s/m; 0 when none), then the count
of planes rendered (0 when none) and their normals, 3 floats each, then whether the planes held
lapsed since they were last rendered (1.0) or not (``LAPSED``; ``BOUND_SIZE`` in all). A lapse
leaves the rest as the last rendered period left it.
"""
import math
from typing import Sequence

import numpy as np

from haptic_contract.checks import finite_number
from haptic_contract.contact_model import ContactModel, Kind, MAX_PLANES
from haptic_contract.plane_law import saturate_components
from haptic_contract.wand import roll_axis
from haptic_wand_driver.model_easing import eased_extra, eased_scale, eased_shift, held_normals, \
    least_shift, matched_extra, matched_shift, scaled_model, spring_push, stored_energy, \
    total_damping, total_stiffness, turned_normals
from haptic_wand_driver.port_passivity import bounded_shift, PortPassivity

__all__ = ['BOUND_SIZE', 'DEADLINE', 'LAPSED', 'LAW_SIZE', 'LocalRenderer', 'MAX_DAMPING_PER_MASS',
           'MODE_NONE', 'MODE_PLANES', 'MODE_WRENCH', 'PLANE_SIZE', 'PLANES_AT', 'SERIAL', 'SINCE',
           'STEP_RATE']

_ZERO = (0.0, 0.0, 0.0)
MAX_DAMPING_PER_MASS = 0.5  # x m/T: an explicit damper is stable below 2 m/T
MODE_NONE, MODE_WRENCH, MODE_PLANES = 0.0, 1.0, 2.0  # what ``packed`` holds
DEADLINE, SINCE, SERIAL, STEP_RATE, PLANES_AT, PLANE_SIZE = 7, 21, 22, 23, 24, 15
LAW_SIZE = PLANES_AT + MAX_PLANES * PLANE_SIZE
BOUND_SIZE = 9 + 3 * MAX_PLANES
LAPSED = BOUND_SIZE - 1
_NOTHING = (None, None, -math.inf)  # (model, wrench, deadline) held


class LocalRenderer:
    """Renders contact models on the device.

    Parameters
    ----------
    force_limit, torque_limit : float
        The device's limits, N and N·m.
    passivity : PortPassivity
        The port's observer and controller, run at the servo rate.
    mass : (3,) float, kg
        The device's apparent mass per axis, for the contact damping.
    contact_damping_ratio : float
        Damping ratio of the contact on the device's mass (0: the material's damping alone).
    model_step_rate : float, N/s
        How fast a new model's spring push eases in (``model_easing``); 0: at once.
    """

    def __init__(self, *, force_limit: float, torque_limit: float, passivity: PortPassivity,
                 mass: Sequence[float] = (0.0, 0.0, 0.0), contact_damping_ratio: float = 0.0,
                 model_step_rate: float = 0.0) -> None:
        self.force_limit = force_limit
        self.torque_limit = torque_limit
        self.passivity = passivity
        self.mass = tuple(mass)
        self.contact_damping_ratio = contact_damping_ratio
        self.model_step_rate = finite_number(model_step_rate, 'model_step_rate', minimum=0.0,
                                             unit='N/s')
        self.packed = np.zeros((2, LAW_SIZE))  # (servo_loop's layout)
        # shift, take, push, stiffness factor and sum, damping added and sum, planes, normals
        self.bound = np.zeros(BOUND_SIZE)
        self.bound[1], self.bound[3] = -1.0, 1.0
        self._held = ((*_NOTHING, 0),) * 2 + (-math.inf,)  # before since, from since, since
        self._takes = 0
        self.clear()

    def take(self, model: ContactModel, deadline: float, since: float = -math.inf) -> None:
        """Render ``model`` until ``deadline``, from the servo period holding ``since``.

        Both are the device's clock (s); ``since`` defaults to the next period.
        """
        mode = MODE_PLANES if model.kind == Kind.PLANES else MODE_NONE
        planes = [value for plane in model.planes for vector in plane for value in vector]
        self._hold((model, None, deadline), since, mode, model.force_limit, model.valid_radius,
                   model.tip, _ZERO * 2, len(model.planes), planes)

    def take_wrench(self, force, torque, deadline: float, since: float = -math.inf) -> None:
        """Render a fixed wrench as ``take`` a model: for a law that has no model to send."""
        self._hold((None, (tuple(force), tuple(torque)), deadline), since, MODE_WRENCH, 0.0, 0.0,
                   _ZERO, (*force, *torque), 0, [])

    def clear(self, since: float = -math.inf) -> None:
        """Drop what is held, as ``take``: zero force until the next model or wrench."""
        self._hold(_NOTHING, since, MODE_NONE, 0.0, 0.0, _ZERO, _ZERO * 2, 0, [])

    def expire(self, deadline: float) -> None:
        """Render what is held now until ``deadline`` (the device's clock, s) at the latest."""
        before, (model, wrench, held_deadline, take), since = self._held
        deadline = min(deadline, held_deadline)
        self.packed[0, DEADLINE] = deadline
        self._held = (before, (model, wrench, deadline, take), since)

    def _hold(self, held: tuple, since: float, mode, force_limit, valid_radius, tip, wrench,
              count, planes) -> None:
        """Hold ``held`` from ``since`` on, and what was held before until then."""
        self._takes += 1
        self.packed[1] = self.packed[0]
        self.packed[0, :PLANES_AT + len(planes)] = (
            self.force_limit, self.torque_limit, self.contact_damping_ratio, *self.mass, mode,
            held[2], force_limit, valid_radius, *tip, *wrench, count, MAX_DAMPING_PER_MASS,
            since, self._takes, self.model_step_rate, *planes)
        self._held = (self._held[1], (*held, self._takes), since)

    def wrench(self, time: float, coordinates: Sequence[float], rates: Sequence[float],
               period: float) -> tuple[tuple, tuple]:
        """Force (N) and torque (N·m, about the tip) to render now, workspace frame.

        ``time`` is the device's clock (s); ``coordinates`` and ``rates`` the joints (x, y, z,
        roll, yaw) and their rates; ``period`` the servo period (s).
        """
        before, held, since = self._held
        model, wrench, deadline, take = held if time + period > since else before
        position, velocity = coordinates[:3], rates[:3]
        force, torque = _ZERO, _ZERO
        limit = self.force_limit
        if wrench is not None and time + period <= deadline:
            force, torque = wrench
            self._forget()
        elif (model is not None and model.kind == Kind.PLANES and time + period <= deadline
                and model.valid(position)):
            x, y, z = roll_axis(coordinates[4])
            spin = (rates[3] * x, rates[3] * y, rates[3] * z + rates[4])
            limit = min(self.force_limit, model.force_limit)
            shift, rendered = self._shift(model, take, coordinates, velocity, period)
            self.bound[LAPSED] = 0.0
            force, torque = scaled_model(rendered, float(self.bound[3]),
                                         float(self.bound[5])).wrench(
                position, velocity, coordinates[3], coordinates[4], spin,
                self._contact_damping(period), limit, shift)
        elif model is not None and model.kind == Kind.PLANES and time + period > deadline:
            self.bound[LAPSED] = 1.0  # what the planes pushed waits for the next model
        else:
            self._forget()
        force = self.passivity.control(force, position, velocity, period,
                                       time + period > deadline)
        return (saturate_components(force, limit),
                saturate_components(torque, self.torque_limit))

    def planes_shift(self, coordinates: Sequence[float]) -> tuple:
        """Return how far (m, workspace frame) the planes are rendered out of the model held.

        Along the first plane's normal: a telerobotic model has one plane, and the remote end
        presses the patient as the hand feels it only if the robot's target is moved out as far.
        Over a lapse, where the next model will start (the push before it, matched where the tool
        now is): the hand sank while it felt nothing, and the robot must not follow it in. Zero
        while no planes are held.
        """
        model = self._held[1][0]
        if model is None or model.kind != Kind.PLANES or not model.planes:
            return _ZERO
        bound, normal = self.bound, model.planes[0].normal
        shift = float(bound[0])
        if bound[7] == len(model.planes):  # the normals rendered, eased toward the model's
            normal = (float(bound[8]), float(bound[9]), float(bound[10]))
        if bound[LAPSED] and self.model_step_rate > 0.0:
            springs = [(d, bound[3] * k) for d, k in held_normals(model, bound[7:]).springs(
                coordinates, coordinates[3], coordinates[4])]
            shift = matched_shift(springs, self._push_to_match(springs))
        return (shift * normal[0], shift * normal[1], shift * normal[2])

    def _push_to_match(self, springs) -> float:
        """Return the push a model's first eased period starts from, on its ``springs``.

        The last period's; after a lapse, no more than the model pushes where the tool now is.
        """
        push = float(self.bound[2])
        return min(push, spring_push(springs, 0.0)) if self.bound[LAPSED] else push

    def _forget(self) -> None:
        """Nothing renders planes now: the next model starts from no push."""
        self.bound[2] = self.bound[4] = self.bound[6] = self.bound[7] = self.bound[LAPSED] = 0.0

    def _shift(self, model: ContactModel, take: int, coordinates: Sequence[float],
               velocity: Sequence[float], period: float) -> tuple[float, ContactModel]:
        """Return the shift of ``model``'s planes this period, and the model to render.

        Set by the port's bound at the model's first period and kept; or, easing, matched to the
        last period's stiffness, damping, normals and push at the first and eased from there
        (the factor, the added damping and the normals with it, in ``bound``), storing no more
        than the port absorbed or the planes held.
        """
        first = take != self.bound[1]
        if not (first or self.model_step_rate > 0.0):
            return float(self.bound[0]), model
        self.passivity.observe(coordinates[:3])
        roll, yaw = coordinates[3], coordinates[4]
        energy = self.passivity.energy
        if self.model_step_rate == 0.0:
            self.bound[:2] = (bounded_shift(model.springs(coordinates, roll, yaw), energy), take)
            return float(self.bound[0]), model
        step = self.model_step_rate * period
        shift, _, push, scale, stiff, extra, damped = self.bound[:7].tolist()
        rendered = held_normals(model, self.bound[7:])
        if first:
            springs = rendered.springs(coordinates, roll, yaw)
            total = total_stiffness(springs)
            scale = stiff / total if stiff > 0.0 and total > 0.0 else 1.0
            extra = matched_extra(rendered, damped)
            springs = [(d, scale * k) for d, k in springs]
            shift = matched_shift(springs, self._push_to_match(springs))
        else:
            held = stored_energy([(d, scale * k) for d, k in rendered.springs(
                coordinates, roll, yaw)], shift)
            rendered = turned_normals(rendered, model, step, push)
            springs = rendered.springs(coordinates, roll, yaw)
            total = total_stiffness(springs)
            scale = eased_scale(scale, step, push)
            extra = eased_extra(extra, step, push, velocity, len(model.planes))
            springs = [(d, scale * k) for d, k in springs]
            eased = eased_shift(springs, shift, step)
            shift = max(eased, least_shift(springs, max(energy, held), min(eased, 0.0)))
        self.bound[:8] = (shift, take, spring_push(springs, shift), scale, scale * total, extra,
                          total_damping(rendered, extra), len(rendered.planes))
        for k, plane in enumerate(rendered.planes):
            self.bound[8 + 3 * k:11 + 3 * k] = plane.normal
        return shift, rendered

    def _contact_damping(self, period: float):
        """Return the per-plane damping for this servo period (None when the ratio is zero)."""
        if self.contact_damping_ratio <= 0.0:
            return None
        ratio, mass = self.contact_damping_ratio, self.mass

        def damping(plane) -> float:
            n, k = plane.normal, plane.stiffness
            stiffness = k[0] * n[0] * n[0] + k[1] * n[1] * n[1] + k[2] * n[2] * n[2]
            inertia = mass[0] * n[0] * n[0] + mass[1] * n[1] * n[1] + mass[2] * n[2] * n[2]
            return min(2.0 * ratio * math.sqrt(stiffness * inertia),
                       MAX_DAMPING_PER_MASS * inertia / period)
        return damping
