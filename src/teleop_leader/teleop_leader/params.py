"""The ROS parameters of the operator site's leader (config/teleop_leader.yaml)."""
from dataclasses import dataclass

from haptic_contract.shared_defaults import FORCE_LIMIT
from haptic_contract.teleop import Scheme, SCHEMES
from haptic_util.parameters import parameter, RealtimeParams
from teleop_protocol.admission import AdmissionConfig

__all__ = ['LeaderParams']


@dataclass(frozen=True)
class LeaderParams(RealtimeParams):
    scheme: str = parameter(Scheme.MODEL.value, 'bilateral scheme', choices=SCHEMES)
    force_scale: float = parameter(0.3, 'felt force per patient force', low=1e-3, high=10.0)
    position_scale: float = parameter(1.0, 'robot motion per wand motion', low=1e-3, high=10.0)
    link_timeout: float = parameter(0.1, 'no feedback for this long: zero force', unit='s',
                                    low=0.001)
    coupling_mass: float = parameter(0.1, 'tdpa: the virtual coupling\'s mass', unit='kg',
                                     low=1e-3, high=10.0)
    coupling_stiffness: float = parameter(400.0, 'tdpa: its spring to the wand', unit='N/m',
                                          low=1.0, high=1e4)
    coupling_damping: float = parameter(9.0, 'tdpa: its damper to the wand', unit='N*s/m',
                                        low=0.0, high=1e3)
    coupling_ground_damping: float = parameter(1.0, 'tdpa: its damper to the world',
                                               unit='N*s/m', low=0.0, high=1e3)
    frame_id: str = parameter('world', 'the wand\'s frame')
    robot_frame: str = parameter('base_link', 'the robot\'s base frame, of the link\'s messages')
    force_limit: float = parameter(FORCE_LIMIT, 'force limit sent with the contact model',
                                   unit='N', low=0.0)
    model_lifetime: float = parameter(0.010, 'a rendered model holds this long after its '
                                      'pose\'s stamp', unit='s', low=0.0005, high=1.0)
    model_valid_radius: float = parameter(0.01, 'a rendered model holds this far from the wand '
                                          '(its valid_radius; the remote site decides where '
                                          'there is a plane)', unit='m', low=1e-4, high=1.0)
    max_feedback_age: float = parameter(AdmissionConfig.max_age, 'after a silence this long, '
                                        'feedback later than the link\'s best by more than '
                                        'this is dropped', unit='s', low=0.001)
    max_stamp_lead: float = parameter(AdmissionConfig.max_lead, 'feedback stamped earlier than '
                                      'the link allows by more than this is refused', unit='s',
                                      low=0.001)
    session_timeout: float = parameter(AdmissionConfig.session_timeout, 'the remote site\'s '
                                       'silence after which another may take over', unit='s',
                                       low=0.01)
