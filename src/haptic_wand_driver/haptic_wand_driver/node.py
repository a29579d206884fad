"""The wand driver node: publishes the tip pose and twist, applies the wrench it receives.

Publishes ``wand/pose`` (PoseStamped) and ``wand/twist`` (TwistStamped) at ``rate``, and applies
each ``wand/wrench`` (WrenchStamped) to the device when it arrives. A wrench older than
``wrench_timeout``, or one with NaN, gives zero force. The wrench's stamp is the stamp of the pose
it answers, so the driver measures the loop's round trip (``stats_file``).
"""
from geometry_msgs.msg import PoseStamped, TwistStamped, WrenchStamped
from rclpy.node import Node

from haptic_util.executor import run_nodes, StartupError
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.qos import HAPTIC_STREAM_QOS
from haptic_util.stamps import to_nanoseconds
from haptic_wand_driver.device import make_device
from haptic_wand_driver.experiments import make_script, needs_scene
from haptic_wand_driver.loop_stats import LoopStats
from haptic_wand_driver.operator import OperatorHand
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.simulated import SimulatedWandConfig
from haptic_wand_driver.wrench_input import WrenchCommand

__all__ = ['WandDriverNode', 'main']

WARN_PERIOD = 1.0  # [s] throttle of repeated warnings


class WandDriverNode(Node):
    """Runs one haptic device: its state out at ``rate``, the rendered wrench in."""

    def __init__(self, **kwargs):
        super().__init__('wand_driver', **kwargs)
        self.params = params = declare_parameters(self, WandDriverParams)
        try:
            self.device = self._make_device(params)
        except ValueError as error:  # includes DeviceUnavailableError and script/replay errors
            raise StartupError(f'{self.get_name()}: {error}') from None
        limits = self.device.limits
        self.wrench = WrenchCommand(force_limit=limits.force_limit,
                                    torque_limit=limits.torque_limit,
                                    timeout=params.wrench_timeout)
        self.stats = LoopStats()
        self._state = None
        self._start_ns = None
        self._pose = PoseStamped()
        self._twist = TwistStamped()
        self._pose.header.frame_id = self._twist.header.frame_id = params.frame_id
        self._pose_pub = self.create_publisher(PoseStamped, 'wand/pose', HAPTIC_STREAM_QOS)
        self._twist_pub = self.create_publisher(TwistStamped, 'wand/twist', HAPTIC_STREAM_QOS)
        self._wrench_sub = self.create_subscription(WrenchStamped, 'wand/wrench', self.on_wrench,
                                                    HAPTIC_STREAM_QOS)
        self.create_timer(1.0 / params.rate, self.tick)
        self.get_logger().info(f'{params.device} wand at {params.rate:g} Hz in frame '
                               f'{params.frame_id!r}; waiting for the loop to connect')

    def _make_device(self, params: WandDriverParams):
        if params.device == 'replay':
            replay = resolve_path(params.replay_file, what='parameter replay_file')
            return make_device('replay', path=replay, loop=params.replay_loop)
        if params.device != 'simulated':
            return make_device(params.device)
        project = None
        if needs_scene(params.experiment):
            project = _surface_projection(
                resolve_path(params.scene_file, what='parameter scene_file'))
        config = SimulatedWandConfig(mass=[params.device_mass] * 3,
                                     damping=[params.device_damping] * 3)
        hand = OperatorHand(make_script(params.experiment, project),
                            stiffness=params.hand_stiffness, damping=params.hand_damping)
        return make_device('simulated', config=config, operator=hand)

    def connected(self) -> bool:
        """Whether the loop is connected, so no pose of the experiment is lost to discovery."""
        return (self._pose_pub.get_subscription_count() >= self.params.min_subscribers
                and (not self.params.wait_for_wrench
                     or self._wrench_sub.get_publisher_count() >= 1))

    def tick(self) -> None:
        now_ns = self.get_clock().now().nanoseconds
        if self._start_ns is None:
            if not self.connected():
                return
            self._start_ns = now_ns
            self.get_logger().info('loop connected: experiment started')
        now = now_ns * 1e-9
        state = self._state = self.device.read(now)
        self.device.apply(*self.wrench.current(now, state.yaw))
        self._publish(state, now_ns)
        duration = self.params.duration
        if duration and now_ns - self._start_ns >= duration * 1e9:
            self.get_logger().info(f'experiment done after {duration:g} s: {self.stats.summary()}')
            self.context.try_shutdown()

    def _publish(self, state, now_ns: int) -> None:
        sec, nanosec = divmod(now_ns, 1_000_000_000)
        pose, twist = self._pose, self._twist
        pose.header.stamp.sec = twist.header.stamp.sec = sec
        pose.header.stamp.nanosec = twist.header.stamp.nanosec = nanosec
        p, q = pose.pose.position, pose.pose.orientation
        p.x, p.y, p.z = (float(v) for v in state.position)
        q.x, q.y, q.z, q.w = (float(v) for v in state.orientation)
        linear, angular = twist.twist.linear, twist.twist.angular
        linear.x, linear.y, linear.z = (float(v) for v in state.linear_velocity)
        angular.x, angular.y, angular.z = (float(v) for v in state.angular_velocity)
        self._pose_pub.publish(pose)
        self._twist_pub.publish(twist)
        self.stats.sent(now_ns)

    def on_wrench(self, msg: WrenchStamped) -> None:
        now_ns = self.get_clock().now().nanoseconds
        stamp_ns = to_nanoseconds(msg.header.stamp)
        self.stats.answered(stamp_ns, now_ns)
        if self._start_ns is None:
            return
        now = now_ns * 1e-9
        state = self._state = self.device.read(now)  # the new wrench acts from its arrival on
        reason = self._take(msg, stamp_ns * 1e-9, now)
        if reason is not None:
            self.get_logger().warn(reason, throttle_duration_sec=WARN_PERIOD)
        self.device.apply(*self.wrench.current(now, state.yaw))

    def _take(self, msg: WrenchStamped, stamp: float, now: float):
        """Hand a received wrench to the command; return why it was refused, or None."""
        if msg.header.frame_id != self.params.frame_id:
            self.wrench.clear()
            return (f'wrench ignored and force zeroed: frame_id {msg.header.frame_id!r} is not '
                    f'{self.params.frame_id!r}')
        f, t = msg.wrench.force, msg.wrench.torque
        return self.wrench.update((f.x, f.y, f.z), (t.x, t.y, t.z), stamp, now)

    def destroy_node(self) -> bool:
        self.device.close()
        if self.params.stats_file:
            self.stats.save(self.params.stats_file)
        self.get_logger().info(f'published {self.stats.poses} poses; loop: {self.stats.summary()}')
        return super().destroy_node()


def _surface_projection(scene_path):
    """``project(point) -> (closest surface point, outward normal)`` on the scene, for scripts."""
    from collision_engine import load_scene

    scene = load_scene(scene_path)

    def project(point):
        result = scene.query(point)
        return result.point, result.normal
    return project


def main(args=None) -> int:
    return run_nodes([WandDriverNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
