"""The force renderer node: collision state in, saturated and passive wrench out.

Subscribes ``collision/state`` (CollisionState) and, when the materials have damping and
``velocity_source`` is ``twist``, ``wand/twist`` (TwistStamped). Publishes one ``wand/wrench``
(WrenchStamped) per state, with the state's header (the pose's stamp and frame), force and torque
about the tip (zero but for a scene's tool, whose face gives one: ``probe``): the reference
wrench, which a device without local rendering applies. With it, one
``wand/contact_model`` (ContactModel): the local model the device renders at its servo rate.
When no fresh state arrives for ``watchdog_timeout``, it publishes zero wrenches (and models that
render nothing). The 1 kHz streams go through ``haptic_util.intra_process``: CDR bytes over DDS,
leaf values within one process.
"""
from typing import Sequence

from geometry_msgs.msg import Point
from rclpy.node import Node
from visualization_msgs.msg import Marker

from force_renderer.assembly import force_law, force_pipeline, passivity_warnings, state_contact
from force_renderer.local_model import local_model
from force_renderer.params import ForceRendererParams
from force_renderer.watchdog import Reason
from haptic_contract.collision_state import STATE, STATUS_NOT_CONVERGED
from haptic_contract.contact_model import MODEL, model_fields
from haptic_contract.graph import (COLLISION_STATE, WAND_CONTACT_MODEL, WAND_FORCE_MARKER,
                                   WAND_TWIST, WAND_WRENCH)
from haptic_contract.streams import stamp_ns, TWIST, TWIST_LINEAR, WRENCH
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.qos import MARKER_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally

__all__ = ['ForceNode', 'main']

_ZERO = (0.0, 0.0, 0.0)

ARROW_SCALE = 0.01  # [m/N] length of the RViz force arrow per newton
DIAGNOSTICS_PERIOD = 1.0  # [s]


class ForceNode(Node):
    """Turns each collision state into the wrench the wand applies."""

    def __init__(self, **kwargs):
        super().__init__('force_renderer', **kwargs)
        self.params = params = declare_parameters(self, ForceRendererParams)
        try:
            law, gains = force_law(params, announce=self.get_logger().info)
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self.pipeline = force_pipeline(params, law)
        for warning in passivity_warnings(params, gains):
            self.get_logger().warn(warning)
        self._contact = None
        self._header = None
        self._twist = None
        self._published = 0
        self._zeroed = Tally()  # zero forces sent, by reason
        self._refused = Tally()  # input that was no message of its type
        self._approximate = 0  # states whose distance is an upper bound (NOT_CONVERGED)
        self._force = self._torque = _ZERO
        self._wrench_pub = stream_publisher(self, WRENCH, WAND_WRENCH)
        self._model_pub = stream_publisher(self, MODEL, WAND_CONTACT_MODEL)
        stream_subscription(self, STATE, COLLISION_STATE, self.on_state,
                            refused=self._refused)
        uses_damping = any(max(damping) > 0.0 for _, damping in gains)
        if uses_damping and params.velocity_source == 'twist':
            stream_subscription(self, TWIST, WAND_TWIST, self.on_twist, refused=self._refused)
        self.create_timer(params.watchdog_timeout / 2, self.check_stale)
        self.diagnostics = Diagnostics(self, self.report, DIAGNOSTICS_PERIOD)
        if params.marker_rate > 0:
            self._marker_pub = self.create_publisher(Marker, WAND_FORCE_MARKER, MARKER_QOS)
            self.create_timer(1.0 / params.marker_rate, self.publish_marker)
        passivity = 'on' if params.passivity else 'off'
        self.get_logger().info(f'{params.law} law, passivity {passivity}, '
                               f'force limit {params.force_limit:g} N')

    def on_twist(self, fields: Sequence) -> None:
        self._twist = (stamp_ns(fields), tuple(fields[TWIST_LINEAR]))

    def on_state(self, fields: Sequence) -> None:
        self._header, stamp, self._contact = state_contact(fields)
        self._approximate += self._contact.status == STATUS_NOT_CONVERGED
        self.render(self._velocity(stamp))

    def _velocity(self, stamp: int):
        """Return the twist of the pose stamped ``stamp`` (ns), or None (then it is estimated)."""
        twist = self._twist
        if twist is None or abs(twist[0] - stamp) > self.params.watchdog_timeout * 1e9:
            return None
        return twist[1]

    def render(self, velocity) -> None:
        now = clock_ns(self.get_clock()) * 1e-9
        force = self.pipeline.step(self._contact, velocity, now)
        reason = self.pipeline.last_reason
        if reason is not Reason.OK:
            self._zeroed.add(reason.value)  # logged at 1 Hz: nothing costly per tick here
        # Even the watchdog's zero carries the stamp of the state it judged, so it never
        # supersedes an answer to a newer pose still on its way to the driver.
        self._force = (float(force[0]), float(force[1]), float(force[2]))
        self._torque = self.pipeline.last_torque
        self._wrench_pub.publish((*self._header, *self._force, *self._torque))
        model = local_model(self.pipeline.law, self._contact, reason is Reason.OK,
                            self.params.model_radius)
        self._model_pub.publish(self._model_fields(model))
        self._published += 1

    def _model_fields(self, model) -> tuple:
        """Return the leaf fields of the ContactModel of ``model`` and the current contact."""
        return model_fields(self._header, self._contact.object, model.kind, model.planes,
                            self.params.force_limit, self.params.model_lifetime,
                            model.valid_radius, self._contact.tip.tolist(),
                            (*self._force, *self._torque))

    def check_stale(self) -> None:
        """Publish zero force while the collision state is stale (after the first one)."""
        if self._contact is None:
            return
        now = clock_ns(self.get_clock()) * 1e-9
        if now - self._contact.stamp > self.params.watchdog_timeout:
            self.render(None)

    def publish_marker(self) -> None:
        if self._contact is None:
            return
        marker = Marker(ns='force', id=0, type=Marker.ARROW, action=Marker.ADD)
        marker.header.stamp.sec, marker.header.stamp.nanosec, marker.header.frame_id = \
            self._header
        tip = self._contact.tip
        start = (float(tip[0]), float(tip[1]), float(tip[2]))
        end = tuple(a + ARROW_SCALE * f for a, f in zip(start, self._force))
        marker.points = [Point(x=start[0], y=start[1], z=start[2]),
                         Point(x=end[0], y=end[1], z=end[2])]
        marker.scale.x, marker.scale.y, marker.scale.z = 0.002, 0.004, 0.004
        marker.color.r, marker.color.g, marker.color.a = 0.1, 0.4, 1.0
        marker.pose.orientation.w = 1.0
        self._marker_pub.publish(marker)

    def report(self) -> Report:
        """Report counts, the watchdog's last word and the passivity energy; log new zeroes."""
        self._zeroed.log_new(lambda line: self.get_logger().warn(f'force zeroed: {line}'))
        self._refused.log_new(lambda line: self.get_logger().warn(f'refused: {line}'))
        reason = self.pipeline.last_reason
        values = {'law': self.params.law, 'published': self._published,
                  'zeroed': self._zeroed.total(), 'refused': self._refused.total(),
                  'approximate': self._approximate,
                  'last_reason': reason.value,
                  **{f'zeroed: {kind}': n for kind, n in self._zeroed.counts.items()}}
        if self.pipeline.passivity is not None:
            values['passivity_energy_j'] = self.pipeline.passivity.energy
        level = OK if reason in (Reason.OK, Reason.NO_STATE) else WARN
        return Report(level, f'force {reason.value}', values)

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        self.get_logger().info(f'published {self._published} wrenches')
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([ForceNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
