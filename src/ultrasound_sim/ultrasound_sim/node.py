"""The ultrasound scanner at the patient's site: the probe's pose in, its B-mode image out.

Takes ``robot/tcp_pose`` (PoseStamped, the robot's 1 kHz stream) and at ``frame_rate`` publishes
``probe/image`` (sensor_msgs/Image, mono8) of the newest pose, stamped with that pose's time, in
``probe_frame`` (``ProbeImaging``). It runs in a process of its own at the remote site, beside the
robot's: in the robot's process, a frame's Python held the robot's 1 kHz loop back for the GIL. The
frame is made in a thread of its own (``LatestWorker``) that yields the cores to the loops
(``idle``, ``niceness``: ``haptic_util.priority``), while the executor's thread takes the newest
pose at each frame (``NewestMessage``: not the other 970 a second), and another thread sends the
frames, at the process's priority. When frames take longer than their period they are dropped,
never queued, and each starts from the newest pose. A pose that cannot be imaged gives a dark
frame, and the reason is logged once a second; a scene or settings that cannot image stop the node
at start, naming what to fix. The kernels are compiled (or loaded) at start, so that the first
frame is not late. Its report gives the frame time and the time from the pose's stamp to the
frame's publication (p50, p99 over the last ``RECENT_FRAMES``).
"""
import collections
import time
from typing import Sequence

import numpy as np
from rclpy.node import Node
from sensor_msgs.msg import Image

from haptic_contract.graph import PROBE_IMAGE, ROBOT_TCP_POSE
from haptic_contract.streams import FRAME, POSE, POSE_ORIENTATION, POSE_POSITION, stamp_ns
from haptic_util.callback_errors import log_callback_error
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.newest import NewestMessage
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.priority import yield_thread
from haptic_util.qos import FRAME_QOS
from haptic_util.stamps import clock_ns
from haptic_util.tally import Tally
from ultrasound_sim.conversions import image_cdr
from ultrasound_sim.latest_worker import LatestWorker
from ultrasound_sim.params import ProbeImagerParams
from ultrasound_sim.probe_imaging import ProbeImaging

__all__ = ['ProbeImagerNode', 'main']

RECENT_FRAMES = 300  # the report's frame times: about the last 10 s at 30 Hz


class ProbeImagerNode(Node):
    """Images the anatomy under the probe at the TCP's newest pose."""

    def __init__(self, **kwargs):
        super().__init__('probe_imager', **kwargs)
        self.params = params = declare_parameters(self, ProbeImagerParams)
        try:
            self.imaging = ProbeImaging.from_scene_file(
                resolve_path(params.scene_file, what='parameter scene_file'),
                params.settings(), params.frame_id)
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        warm_up = self.imaging.warm_up()
        self._pose = None  # the newest TCP pose's fields
        self._published = 0
        self._dark = Tally()
        self._refused = Tally()
        # (frame wall, frame CPU, pose stamp to publication) s, per frame
        self._times = collections.deque(maxlen=RECENT_FRAMES)
        self._clock = self.get_clock()
        self._publisher = self.create_publisher(Image, PROBE_IMAGE, FRAME_QOS)
        self._poses = NewestMessage(self, POSE, ROBOT_TCP_POSE, refused=self._refused)
        # Frames are made in one thread, which yields the cores, and sent from another, which
        # does not: the EventsExecutor has no guard condition to wake its own thread with.
        self._sender = LatestWorker(self.publish_frame, on_error=log_callback_error,
                                    name='probe_image_sender')
        self._worker = LatestWorker(self.make_frame, on_error=log_callback_error,
                                    on_start=self.yield_cores, name='probe_imager')
        self.create_timer(1.0 / params.frame_rate, self.on_timer)
        self.diagnostics = Diagnostics(self, self.report, 1.0)
        settings = self.imaging.imager.settings
        self.get_logger().info(
            f'{settings.probe_type} probe at {settings.centre_frequency / 1e6:g} MHz, '
            f'{1e3 * settings.depth:g} mm deep, {settings.scanlines} lines; '
            f'{params.frame_rate:g} frames/s on probe/image (kernels ready in {warm_up:.2f} s)')

    def yield_cores(self) -> None:
        """Let the site's loops go first for the cores (in the worker's thread)."""
        priority = yield_thread(self.params.niceness, self.params.idle)
        self.get_logger().info(f'frames made at {priority}')

    def on_timer(self) -> None:
        """Hand the newest pose to the worker, if one came since the last."""
        pose = self._poses.take()
        if pose is not None:
            self._pose = pose
            self._worker.offer(pose)

    def make_frame(self, pose: Sequence) -> None:
        """Image one pose, and hand it to the sender (in the worker's thread).

        The worker may be starved for the cores: it never holds the middleware's locks.
        """
        started, cpu = time.perf_counter(), time.thread_time()
        imaged = self.imaging.image(pose[FRAME], pose[POSE_POSITION], pose[POSE_ORIENTATION])
        if imaged.reason:
            self._dark.add('dark frame', imaged.reason)
        stamp = stamp_ns(pose)
        frame = image_cdr(stamp, self.params.probe_frame, imaged.image)
        self._sender.offer((frame, stamp, time.perf_counter() - started,
                            time.thread_time() - cpu))

    def publish_frame(self, made: tuple) -> None:
        """Publish a frame made (in the sender's thread)."""
        frame, stamp, wall, cpu = made
        self._publisher.publish(frame)
        self._published += 1
        self._times.append((wall, cpu, 1e-9 * (clock_ns(self._clock) - stamp)))

    def report(self) -> Report:
        self._dark.log_new(self.get_logger().warn)
        self._refused.log_new(lambda line: self.get_logger().warn(f'poses refused: {line}'))
        times = np.array(list(self._times)).reshape(-1, 3)
        wall, cpu, latency = (np.percentile(times, (50, 99), axis=0) if len(times)
                              else np.full((2, 3), np.nan)).T
        values = {'published': self._published, 'dark': self._dark.total(),
                  'replaced': self._worker.replaced, 'frame_p50_s': wall[0],
                  'frame_p99_s': wall[1], 'frame_cpu_p50_s': cpu[0],
                  'pose_to_publication_p50_s': latency[0],
                  'pose_to_publication_p99_s': latency[1]}
        if self._pose is None:
            return Report(WARN, 'waiting for robot/tcp_pose', values)
        return Report(OK, f'{self._published} frames; frame time p50 {1e3 * wall[0]:.1f} ms, '
                      f'p99 {1e3 * wall[1]:.1f} ms; pose to publication p99 '
                      f'{1e3 * latency[1]:.1f} ms', values)

    def destroy_node(self) -> bool:
        self._worker.close()
        self._sender.close()
        self._poses.destroy()
        self.diagnostics.final()
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([ProbeImagerNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
