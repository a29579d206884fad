"""The collision node: tip pose in, signed distance to the nearest scene object out.

Subscribes ``wand/pose`` (PoseStamped) and publishes, per pose, ``collision/state``
(CollisionState) with the pose's header, so that latency can be measured end to end. When
the scene mounts a tool, the whole pose places it and the state carries its face (``probe``).
Optionally ``collision/nearby`` (every object within ``report_radius``), ``collision/markers``
for RViz, ``scene/description`` (the scene YAML, latched, for recorders) and ``/diagnostics``.

The 1 kHz streams go through ``haptic_util.intra_process``: CDR bytes over DDS (converting
message objects cost about half of the node's CPU), leaf values within one process.
"""
import time
from typing import Sequence

from rclpy.node import Node
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from collision_engine import load_scene, read_scene
from collision_engine.conversions import (invalid_state, InvalidPose, POSE, STATE, state, tip_pose,
                                          tool_state)
from collision_engine.markers import contact_markers, scene_markers
from collision_engine.params import CollisionNodeParams
from collision_engine.probe import query_probe
from haptic_contract.graph import (COLLISION_MARKERS, COLLISION_NEARBY, COLLISION_STATE,
                                   SCENE_DESCRIPTION, WAND_POSE)
from haptic_contract.streams import header as stamped_header
from haptic_msgs.msg import CollisionStateArray
from haptic_util.diagnostics import Diagnostics, OK, Report, WARN
from haptic_util.executor import run_nodes, StartupError
from haptic_util.intra_process import stream_publisher, stream_subscription
from haptic_util.parameters import declare_parameters
from haptic_util.paths import resolve_path
from haptic_util.qos import HAPTIC_STREAM_QOS, LATCHED_QOS, MARKER_QOS
from haptic_util.tally import Tally

__all__ = ['CollisionNode', 'main']


class CollisionNode(Node):
    """Answers every tip pose with the signed distance to the nearest scene object."""

    def __init__(self, **kwargs):
        super().__init__('collision_engine', **kwargs)
        self.params = declare_parameters(self, CollisionNodeParams)
        scene_path = resolve_path(self.params.scene_file, what='parameter scene_file')
        try:
            self.scene = load_scene(scene_path, announce=self.get_logger().info)
        except ValueError as error:
            raise StartupError(f'{self.get_name()}: {error}') from None
        self.get_logger().info(
            f'scene {scene_path}: {len(self.scene.objects)} object(s) in frame '
            f'{self.scene.frame_id!r}')

        self._answered = 0
        self._refused = Tally()  # poses answered with an invalid state, by fault
        self._last_result = None
        self._state_pub = stream_publisher(self, STATE, COLLISION_STATE)
        self._nearby_pub = (self.create_publisher(CollisionStateArray, COLLISION_NEARBY,
                                                  HAPTIC_STREAM_QOS)
                            if self.params.report_radius > 0 else None)
        stream_subscription(self, POSE, WAND_POSE, self.on_pose, refused=self._refused)

        description = self.create_publisher(String, SCENE_DESCRIPTION, LATCHED_QOS)
        description.publish(String(data=scene_path.read_text()))
        self.diagnostics = Diagnostics(self, self.report, self.params.diagnostics_period)
        if self.params.marker_rate > 0:
            self._marker_pub = self.create_publisher(MarkerArray, COLLISION_MARKERS, MARKER_QOS)
            self._scene_markers = scene_markers(read_scene(scene_path))
            self.create_timer(1.0 / self.params.marker_rate, self.publish_markers)

    def on_pose(self, pose: Sequence) -> None:
        header = stamped_header(pose)
        disagreements = self.scene.cross_validation_disagreements
        try:
            tip, orientation = tip_pose(pose, self.scene.frame_id)
        except InvalidPose as error:
            self._refused.add(error.kind, str(error))
            self._state_pub.publish(invalid_state(header, disagreements))
            return
        start = time.perf_counter()
        if self.scene.tool is None:
            result = self.scene.query(tip)
            elapsed = time.perf_counter() - start
            fields = state(header, result, elapsed, disagreements, orientation)
        else:
            probe = query_probe(self.scene, tip, orientation)
            elapsed = time.perf_counter() - start
            result = probe.tool
            fields = tool_state(header, probe, tip, orientation, elapsed, disagreements)
        self._last_result = result
        self._state_pub.publish(fields)
        self._answered += 1
        if self._nearby_pub is not None:
            self.publish_nearby(header, tip)

    def publish_nearby(self, header: tuple, tip) -> None:
        disagreements = self.scene.cross_validation_disagreements
        nearby = CollisionStateArray(radius=self.params.report_radius)
        nearby.header.stamp.sec, nearby.header.stamp.nanosec, nearby.header.frame_id = header
        nearby.states = [STATE.to_message(state(header, result, 0.0, disagreements))
                         for result in self.scene.query_within(tip, self.params.report_radius)]
        self._nearby_pub.publish(nearby)

    def publish_markers(self) -> None:
        stamp = self.get_clock().now().to_msg()
        markers = MarkerArray(markers=self._scene_markers + contact_markers(
            self._last_result, self.scene.frame_id))
        for marker in markers.markers:
            marker.header.stamp = stamp
        self._marker_pub.publish(markers)

    def report(self) -> Report:
        """Report counts and the FCL cross-validation totals, for /diagnostics."""
        stats = self.scene.cross_validation_stats
        self._refused.log_new(lambda line: self.get_logger().error(f'poses refused: {line}'))
        values = {'objects': len(self.scene.objects),
                  'published': self._answered + self._refused.total(),
                  'invalid_poses': self._refused.total(),
                  **{f'refused: {kind}': n for kind, n in self._refused.counts.items()}}
        if stats is None:
            return Report(OK, 'FCL cross-validation off', values)
        values.update(fcl_checks=stats.checks, fcl_disagreements=stats.disagreements,
                      fcl_max_discrepancy_m=stats.max_discrepancy, fcl_errors=stats.errors,
                      fcl_dropped=stats.dropped, sign_checks=stats.sign_checks,
                      sign_disagreements=stats.sign_disagreements)
        return Report(WARN if stats.disagreements else OK,
                      f'{stats.disagreements} FCL disagreement(s) in {stats.checks} check(s)',
                      values)

    def destroy_node(self) -> bool:
        self.scene.close()  # the FCL cross-check's worker thread
        self.diagnostics.final()
        self.get_logger().info(f'answered {self._answered} poses, refused '
                               f'{self._refused.total()}')
        return super().destroy_node()


def main(args=None) -> int:
    return run_nodes([CollisionNode], args)


if __name__ == '__main__':
    raise SystemExit(main())
