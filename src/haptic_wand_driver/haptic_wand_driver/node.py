"""The wand driver node: publishes the tip pose and twist, applies the wrench it receives.

Publishes ``wand/pose`` (PoseStamped) and ``wand/twist`` (TwistStamped) at ``rate``, and applies
each ``wand/wrench`` (WrenchStamped) to the device when it arrives. A wrench older than
``wrench_timeout``, or one with NaN, gives zero force; while the next pose is late, the answer to
the newest one may hold longer (``hold_while_late``, ``answer_deadline``). The wrench's stamp is
the stamp of the pose it answers, so the driver measures the loop's round trip (``stats_file``).
Once the loop is closed it publishes ``wand/session_start`` (Header, latched): the instant its
experiment's clock starts, which whatever acts on a scripted session at set times counts from.
"""
import enum
import math
import pathlib
import time
from typing import Sequence

import numpy as np
from rclpy.node import Node
from std_msgs.msg import Bool, Header

from haptic_contract.contact_model import ContactModel, Kind, MODEL, ModelRefused
from haptic_contract.graph import (WAND_APPLIED_WRENCH, WAND_CONTACT_MODEL, WAND_MODEL_SHIFT,
                                   WAND_POSE, WAND_SESSION_START, WAND_TWIST, WAND_WRENCH)
from haptic_contract.streams import (frame, POSE, stamp_ns, TWIST, VECTOR, WRENCH, WRENCH_FORCE,
                                     WRENCH_TORQUE)
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import request_stop, run_nodes, StartupError
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.qos import LATCHED_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from haptic_wand_driver.answer_deadline import AnswerDeadline
from haptic_wand_driver.assembly import local_renderer, make_wand, port_passivity
from haptic_wand_driver.device import LocalRenderingUnsupported
from haptic_wand_driver.device_clock_map import DeviceClockMap
from haptic_wand_driver.local_rendering import LocalRenderer
from haptic_wand_driver.loop_stats import LoopStats
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.wrench_input import Refusal, WrenchCommand

__all__ = ['WandDriverNode', 'main']

DIAGNOSTICS_PERIOD = 1.0  # [s]
IN_FLIGHT_GRACE = 0.05  # [s] after the last pose, for its answer to arrive
BEHIND_RATE = 0.95  # of the set rate: below it, the loop is reported behind
BEHIND_ANSWERED = 99.0  # [%] of the poses since the last report: below it, behind too


class Phase(enum.Enum):
    """A session: wait for the consumers, probe the loop at rest, run, done."""

    WAITING = 'waiting'
    PROBING = 'probing'
    RUNNING = 'running'
    DONE = 'done'


class WandDriverNode(Node):
    """Runs one haptic device: its state out at ``rate``, the rendered wrench in."""

    def __init__(self, **kwargs):
        super().__init__('wand_driver', **kwargs)
        self.params = params = declare_parameters(self, WandDriverParams)
        try:
            self.device = make_wand(params, announce=self.get_logger().info)
        except ValueError as error:  # includes DeviceUnavailableError and script/replay errors
            raise StartupError(f'{self.get_name()}: {error}') from None
        limits = self.device.limits
        self.wrench = WrenchCommand(force_limit=limits.force_limit,
                                    torque_limit=limits.torque_limit,
                                    timeout=params.wrench_timeout)
        self._record = (pathlib.Path(f'{params.stats_file}.part') if params.stats_file
                        else None)
        self.stats = LoopStats(record=self._record)
        self._clock_map = DeviceClockMap()  # maps the device's record of its force to ROS time
        # The observer always runs (its books are the port's energy figures); the controller acts
        # only when enabled.
        self.passivity = port_passivity(params)
        self.renderer = self._local_renderer() if params.rendering == 'local' else None
        self.answers = AnswerDeadline(params.hold_while_late)
        self._applied = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))  # the wrench the device holds
        self._model_stamp = -math.inf  # of the newest model taken
        self._since = -math.inf  # the device's clock when the renderer last switched
        self._period = 1.0 / params.rate
        self._phase = Phase.WAITING
        self._state = None
        self._probe_start = self._device_offset = 0.0
        self._last_probe_ns = -1
        self._published = 0
        self._refused = Tally()  # wrenches not taken, by fault
        self._reported = (time.monotonic(), 0, 0)  # when, poses and answers at the last report
        self._recorder_ready = False
        self._pose_pub = stream_publisher(self, POSE, WAND_POSE)
        self._twist_pub = stream_publisher(self, TWIST, WAND_TWIST)
        self._applied_pub = stream_publisher(self, WRENCH, WAND_APPLIED_WRENCH)
        self._session_pub = self.create_publisher(Header, WAND_SESSION_START, LATCHED_QOS)
        # One answer per pose: the model when the device renders it (a model carries the wrench
        # of a law that has none), else the wrench. A stream it does not use costs a core's
        # percent or more at 1 kHz, for the publisher and for this node.
        answers = ((MODEL, WAND_CONTACT_MODEL, self.on_model)
                   if self.renderer is not None else
                   (WRENCH, WAND_WRENCH, self.on_wrench))
        self._answer_sub = stream_subscription(self, *answers, refused=self._refused)
        self._shift_pub = (None if self.renderer is None else
                           stream_publisher(self, VECTOR, WAND_MODEL_SHIFT))
        if params.wait_for_recorder:
            self.create_subscription(Bool, 'recorder/ready', self.on_recorder_ready, LATCHED_QOS)
        self.create_timer(1.0 / params.rate, self.tick)
        self.diagnostics = Diagnostics(self, self.report, DIAGNOSTICS_PERIOD)
        rendering = 'local' if self.renderer is not None else 'remote'
        self.get_logger().info(f'{params.device} wand at {params.rate:g} Hz in frame '
                               f'{params.frame_id!r}, {rendering} rendering; waiting for the loop '
                               'to connect')

    def _local_renderer(self) -> LocalRenderer | None:
        """Return the device's servo-rate law, or None (logged) if the device cannot run one."""
        renderer = local_renderer(self.params, self.device.limits, self.passivity)
        try:
            self.device.render_locally(renderer)
        except LocalRenderingUnsupported as error:
            self.get_logger().warn(f'rendering local: {error}; it applies the wrench instead')
            return None
        return renderer

    def ready(self) -> bool:
        """Whether every consumer is connected, so no pose of the session is lost to discovery."""
        params = self.params
        return (self._pose_pub.get_subscription_count() >= params.min_subscribers
                and (not params.wait_for_wrench or self._answer_sub.get_publisher_count() >= 1)
                and (not params.wait_for_recorder or self._recorder_ready))

    def tick(self) -> None:
        now_ns = clock_ns(self.get_clock())
        now = now_ns * 1e-9
        if self._phase is Phase.WAITING:
            if not self.ready():
                return
            self._probe_start = time.monotonic()
            self._state = self.device.read(self._probe_start)
            if not self.params.wait_for_wrench:
                self._run()
            else:
                self._phase = Phase.PROBING
                self.get_logger().info('loop connected: probing it end to end')
        if self._phase is Phase.PROBING:
            self._publish(self._state, now_ns)  # the device at rest where it starts
        elif self._phase is Phase.RUNNING:
            device_now = self._device_time()
            state = self._state = self.device.read(device_now)
            if self._record is not None:
                self._clock_map.observe(device_now, self._ros_minus_device(),
                                        self._ros_minus_device_estimate)
            if self.renderer is None:
                self._apply(now, state)
            self.stats.sent(now_ns)
            self._publish(state, now_ns)
            if self.answers.sent(now, clock_ns(self.get_clock()) * 1e-9):
                self._rearm()  # out and not answered yet: the held answer stops holding
            if self.params.duration and device_now - self._probe_start >= self.params.duration:
                self._phase = Phase.DONE
                self.get_logger().info(f'experiment done after {self.params.duration:g} s')
                # The last poses are still on their way round: let their wrenches come back.
                self.create_timer(IN_FLIGHT_GRACE, request_stop)

    def _device_time(self) -> float:
        """Return the device's clock [s]: monotonic, and skipping the probing.

        A step of the system clock (NTP, a user) must not move or stall the wand.
        """
        return time.monotonic() - self._device_offset

    def _ros_minus_device(self) -> float:
        """Return ROS time minus the device's clock [s], never less than it truly is.

        A deadline on a stamp (ROS time) goes to the device's clock through this. The device's
        clock is read first: a pause between the two reads then makes the deadline early, never
        late (read the other way round, a machine busy with two CPU hogs once let a model push
        13 µs past its lifetime).
        """
        device = self._device_time()
        return clock_ns(self.get_clock()) * 1e-9 - device

    def _ros_minus_device_estimate(self, reads: int = 100) -> float:
        """Return ROS time minus the device's clock [s] as precisely as it can be read.

        For the record (``DeviceClockMap``), not a deadline: the midpoint of the narrowest of
        ``reads`` brackets of ROS time between two readings of the device's clock.
        """
        width, estimate = math.inf, 0.0
        for _ in range(reads):
            before = self._device_time()
            ros = clock_ns(self.get_clock()) * 1e-9
            after = self._device_time()
            if after - before < width:
                width, estimate = after - before, ros - 0.5 * (before + after)
        return estimate

    def _run(self) -> None:
        """Start the session: once an answer came back for a probe, or at once when open loop."""
        self._phase = Phase.RUNNING
        self._device_offset = time.monotonic() - self._probe_start
        self._session_pub.publish(Header(stamp=self.get_clock().now().to_msg(),
                                         frame_id=self.params.frame_id))
        self.get_logger().info('loop closed: experiment started')

    def _publish(self, state, now_ns: int) -> None:
        """Publish the state and what the device applied; its answer may come back inside.

        The twist and the planes' shift go before the pose, and the pose is counted as sent
        before any: in one process the pose's answer is computed (with this twist and shift) and
        delivered inside the pose's ``publish``.
        """
        header = (*divmod(now_ns, 1_000_000_000), self.params.frame_id)
        force, torque = self.device.applied()  # what the hand felt since the last tick
        self._published += 1
        self._last_probe_ns = now_ns
        self._twist_pub.publish((*header, *state.linear_velocity.tolist(),
                                 *state.angular_velocity.tolist()))
        if self._shift_pub is not None:  # before the pose, whose answer may come inside
            self._shift_pub.publish((*header, *self.renderer.planes_shift(
                (*state.position.tolist(), state.roll, state.yaw))))
        self._pose_pub.publish((*header, *state.position.tolist(),
                                *state.orientation.tolist()))
        self._applied_pub.publish((*header, *force.tolist(), *torque.tolist()))

    def on_wrench(self, wrench: Sequence) -> None:
        """Apply a wrench (remote rendering): held, kept passive, until its deadline."""
        now_ns = clock_ns(self.get_clock())
        stamp = stamp_ns(wrench)
        if not self._answered(stamp, now_ns):
            return
        now = now_ns * 1e-9
        state = self._state = self.device.read(self._device_time())  # acts from now on
        refusal = self._take(wrench, stamp * 1e-9, now)
        if refusal is not None:
            self._refused.add(refusal.kind, refusal)  # logged at 1 Hz: cheap on this path
        else:
            self.answers.taken(stamp * 1e-9, self.params.wrench_timeout)
        self._apply(now, state)

    def on_model(self, fields: Sequence) -> None:
        """Hand a contact model to the device's renderer; a bad one gives zero force."""
        now_ns = clock_ns(self.get_clock())
        stamp = stamp_ns(fields)
        if not self._answered(stamp, now_ns):
            return
        try:
            model = ContactModel.from_fields(fields, self.params.frame_id)
        except ModelRefused as refusal:
            self._refused.add(f'model: {refusal.field}', refusal)
            self.renderer.clear(self._arrival())
            return
        if model.stamp < self._model_stamp:
            self._refused.add('model older than the held one')
            return
        self._model_stamp = model.stamp
        since = self._arrival()
        # From the nanoseconds, as the pose's was: seconds plus nanoseconds round otherwise.
        self.answers.taken(stamp * 1e-9, model.valid_for)
        deadline = self.answers.deadline - self._ros_minus_device()
        if model.kind == Kind.UNAVAILABLE:
            self.renderer.take_wrench(model.held_wrench[:3], model.held_wrench[3:], deadline,
                                      since)
        else:
            self.renderer.take(model, deadline, since)

    def _arrival(self) -> float:
        """Return the device's clock now, for the renderer to switch at.

        The renderer holds one switch at a time, so a device yet to run the period of the last
        one (the simulated wand runs its periods on each read) is advanced to now first: only
        when two answers arrive between ticks, no longer at every arrival.
        """
        now = self._device_time()
        if self._since >= self._state.time:
            self._state = self.device.read(now)
        self._since = now
        return now

    def _answered(self, stamp_ns: int, now_ns: int) -> bool:
        """Count an answer to the pose stamped ``stamp_ns``; return whether the device uses it.

        While probing, an answer to a probe closes the loop and starts the session. Answers to
        the last poses, after the experiment, are counted and not used.
        """
        if self._phase is Phase.PROBING:
            if stamp_ns <= self._last_probe_ns:
                self._run()
            return False
        self.stats.answered(stamp_ns, now_ns)
        return self._phase is Phase.RUNNING

    def _apply(self, now: float, state) -> None:
        """Apply the held wrench, kept passive, armed with its deadline as the device watchdog.

        ``now`` is ROS time, the clock of the stamps.
        """
        force, torque = self.wrench.current(now, state.yaw, self.answers.deadline)
        force = self.passivity.control(force, state.position, state.linear_velocity,
                                       self._period)
        self._applied = (force, torque)
        self.device.apply(force, torque, until=self.answers.deadline - self._ros_minus_device())

    def _rearm(self) -> None:
        """Give what the device holds the held answer's deadline, once that moved."""
        until = self.answers.deadline - self._ros_minus_device()
        if self.renderer is not None:
            self.renderer.expire(until)
        else:
            self.device.apply(*self._applied, until=until)

    def _take(self, wrench: list, stamp: float, now: float) -> Refusal | None:
        """Hand a received wrench (``WRENCH`` leaves) to the command; return why it was refused."""
        if frame(wrench) != self.params.frame_id:
            self.wrench.clear()
            return Refusal('wrench in an unknown frame', f'wrench ignored and force zeroed: '
                           f'frame_id {frame(wrench)!r} is not {self.params.frame_id!r}')
        return self.wrench.update(wrench[WRENCH_FORCE], wrench[WRENCH_TORQUE], stamp, now)

    def on_recorder_ready(self, msg: Bool) -> None:
        self._recorder_ready = msg.data

    def report(self) -> Report:
        """Report the session's phase, counts and round trip, for /diagnostics.

        WARN when, since the last report, the loop fell behind: poses went out below 95 % of the
        rate, or fewer than 99 % of them were answered.
        """
        self._refused.log_new(lambda line: self.get_logger().warn(f'wrenches refused: {line}'))
        summary = self.stats.summary()
        then, poses_then, answers_then = self._reported
        self._reported = (time.monotonic(), self.stats.poses, self.stats.answers)
        poses, answers = self.stats.poses - poses_then, self.stats.answers - answers_then
        rate = poses / max(self._reported[0] - then, 1e-9)
        answered = 100.0 * answers / poses if poses else 100.0
        behind = self._phase is Phase.RUNNING and (rate < BEHIND_RATE * self.params.rate
                                                   or answered < BEHIND_ANSWERED)
        values = {'phase': self._phase.value, 'published': self._published,
                  'recent_rate_hz': rate, 'recent_answered_percent': answered,
                  'refused': self._refused.total(), 'late_poses': self.answers.late,
                  **{f'refused: {kind}': n for kind, n in self._refused.counts.items()},
                  'port_net_work_j': self.passivity.net_work, **summary}
        return Report(WARN if behind else OK,
                      f'{self._phase.value}{": behind" if behind else ""}: {rate:.0f} Hz, '
                      f'{answered:.1f} % answered since the last report, recent p99 '
                      f'{1e3 * summary["latency_p99_s"]:.2f} ms', values)

    def destroy_node(self) -> bool:
        self.diagnostics.final()
        self.device.close()
        if self._record is not None:
            self.stats.save(self.params.stats_file, published=self._published,
                            port_net_work_j=self.passivity.net_work, **self._force_edges())
            self._record.unlink()
        self.get_logger().info(f'published {self._published} poses; experiment loop: '
                               f'{self.stats.summary()}')
        return super().destroy_node()

    def _force_edges(self) -> dict:
        """Return the device's own record of its force switching on and off, ROS time [ns].

        Each instant is mapped with the offset of its own stretch between steps of the system
        clock (``DeviceClockMap``); ``clock_steps`` says how many there were.
        """
        edges = getattr(self.device, 'force_edges', [])
        self._clock_map.observe(self._device_time(), self._ros_minus_device(),
                                self._ros_minus_device_estimate)
        times = self._clock_map.to_ros_ns([t for t, _ in edges])
        pushing = np.array([p for _, p in edges], dtype=bool)
        return {'force_on_ns': times[pushing], 'force_off_ns': times[~pushing],
                'clock_steps': np.int64(self._clock_map.steps)}


def main(args=None) -> int:
    return run_nodes([WandDriverNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
