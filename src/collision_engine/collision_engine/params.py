"""The collision node's ROS parameters, in one place (see config/collision_engine.yaml)."""
from dataclasses import dataclass

from haptic_contract.shared_defaults import DEFAULT_SCENE
from haptic_util.parameters import parameter, RealtimeParams

__all__ = ['CollisionNodeParams']


@dataclass(frozen=True)
class CollisionNodeParams(RealtimeParams):
    scene_file: str = parameter(DEFAULT_SCENE, 'scene YAML: a path or package://<pkg>/<path>')
    report_radius: float = parameter(
        0.0, 'also publish every object within this signed distance on collision/nearby '
        '(0 = nearest object only)', unit='m', low=0.0)
    marker_rate: float = parameter(
        10.0, 'rate of RViz markers (scene and contact); 0 disables them', unit='Hz',
        low=0.0, high=100.0)
    diagnostics_period: float = parameter(
        1.0, 'period of the /diagnostics summary', unit='s', low=0.1, high=60.0)
