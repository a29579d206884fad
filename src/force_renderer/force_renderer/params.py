"""The force renderer's ROS parameters, in one place (see config/force_renderer.yaml)."""
from dataclasses import dataclass

from haptic_contract.shared_defaults import DEFAULT_SCENE, DEVICE_DAMPING, FORCE_LIMIT, \
    LOOP_PERIOD
from haptic_util.parameters import parameter, RealtimeParams

__all__ = ['ForceRendererParams', 'LAWS']

LAWS = ('normal', 'centroid', 'proxy')


@dataclass(frozen=True)
class ForceRendererParams(RealtimeParams):
    law: str = parameter('normal', 'normal: spring-damper along the surface normal; proxy: '
                         'god-object proxy (no pop-through); centroid: the paper\'s law, for '
                         'comparison only', choices=LAWS)
    scene_file: str = parameter(DEFAULT_SCENE, 'scene YAML for per-object materials (and the '
                                'proxy and centroid laws); empty: stiffness and damping below '
                                'for all')
    stiffness: tuple[float, ...] = parameter((160.0, 160.0, 160.0), 'K per world axis, for '
                                             'objects without a material', unit='N/m', low=0.0,
                                             length=3)
    damping: tuple[float, ...] = parameter((0.8, 0.8, 0.8), 'C per world axis, in contact only, '
                                           'for objects without a material', unit='N*s/m',
                                           low=0.0, length=3)
    force_limit: float = parameter(FORCE_LIMIT, 'device force limit (saturation)', unit='N',
                                   low=0.0)
    passivity: bool = parameter(True, 'time-domain passivity observer and controller')
    device_damping: float = parameter(DEVICE_DAMPING, 'the device\'s physical damping b, for the '
                                      'passivity bound', unit='N*s/m', low=0.0)
    servo_period: float = parameter(LOOP_PERIOD, 'servo period T, for the passivity bound and '
                                    'controller', unit='s', low=1e-5, high=0.1)
    max_damping: float = parameter(100.0, 'largest damping the passivity controller adds',
                                   unit='N*s/m', low=0.0)
    watchdog_timeout: float = parameter(0.010, 'no fresh collision state for this long: zero '
                                        'force', unit='s', low=0.0005, high=1.0)
    model_radius: float = parameter(0.0005, 'contact models: planes are sent within this '
                                    'distance of a surface, and hold this far from the tip',
                                    unit='m', low=1e-5, high=0.1)
    model_lifetime: float = parameter(0.010, 'contact models hold this long after their '
                                      'pose\'s stamp', unit='s', low=0.0005, high=1.0)
    velocity_source: str = parameter('twist', 'twist: the driver\'s wand/twist; estimate: from '
                                     'the stamped tip positions', choices=('twist', 'estimate'))
    marker_rate: float = parameter(10.0, 'rate of the RViz force arrow; 0 disables it',
                                   unit='Hz', low=0.0, high=100.0)
