"""The ROS parameters of the robot site's nodes (config/robot_site.yaml)."""
from dataclasses import dataclass

from haptic_contract.teleop import HAND_SPEED, Scheme, SCHEMES
from haptic_util.parameters import parameter, RealtimeParams
from robot_site.force_envelope import EnvelopeConfig
from robot_site.model_estimation import EstimatorConfig
from robot_site.safety import SafetyConfig
from teleop_protocol.admission import AdmissionConfig

__all__ = ['envelope', 'FollowerParams', 'PatientBoundParams', 'SimulatedRobotParams']


def envelope(params, hard_stop: float = float('inf')) -> EnvelopeConfig:
    """Return the force envelope ``params`` (a ``PatientBoundParams``) set, with ``hard_stop``."""
    return EnvelopeConfig(hard_stop=hard_stop, rise_rate=params.rise_rate,
                          contact_ramp=params.contact_ramp, contact_force=params.contact_force)


@dataclass(frozen=True)
class PatientBoundParams:
    """The patient's force bound, which the robot and the node commanding it both enforce."""

    max_patient_force: float = parameter(SafetyConfig.max_patient_force, 'each target is kept '
                                         'within the reach of the TCP at which the robot\'s '
                                         'spring presses this hard', unit='N', low=0.1)
    force_margin: float = parameter(SafetyConfig.force_margin, 'the spring stays this far below '
                                    'the limit', unit='N', low=0.0)
    release_force: float = parameter(SafetyConfig.release_force, 'retraction stops below this '
                                     'force', unit='N', low=0.0)
    retract_speed: float = parameter(SafetyConfig.retract_speed, 'retraction speed', unit='m/s',
                                     low=1e-4)
    rise_rate: float = parameter(EnvelopeConfig.rise_rate, 'in contact, the robot\'s spring '
                                 'rises at most this fast', unit='N/s', low=1e-3)
    contact_ramp: float = parameter(EnvelopeConfig.contact_ramp, 'after the first touch, the '
                                    'spring stays under a ramp to the limit this long (0: none)',
                                    unit='s', low=0.0)
    contact_force: float = parameter(EnvelopeConfig.contact_force, 'a measured force above this '
                                     'is contact (for the rate and the ramp)', unit='N', low=0.0)


@dataclass(frozen=True)
class SimulatedRobotParams(PatientBoundParams, RealtimeParams):
    rate: float = parameter(1000.0, 'TCP pose and F/T wrench publishing rate', unit='Hz',
                            low=1.0, high=10000.0)
    frame_id: str = parameter('base_link', 'the robot\'s base frame, also the scene\'s frame')
    scene_file: str = parameter('package://collision_engine/scenes/phantom.yaml',
                                'the patient: a collision scene whose skin the probe presses')
    tissue_stiffness: float = parameter(2000.0, 'Hunt-Crossley k of F = k x^n + lambda x^n xdot',
                                        unit='N/m^n', low=0.0)
    tissue_exponent: float = parameter(1.3, 'Hunt-Crossley n', low=1.0, high=3.0)
    tissue_damping: float = parameter(1500.0, 'Hunt-Crossley lambda', unit='N*s/m^(n+1)',
                                      low=0.0)
    mass: float = parameter(2.0, 'apparent Cartesian mass at the TCP', unit='kg', low=1e-3)
    stiffness: float = parameter(1500.0, 'Cartesian impedance stiffness', unit='N/m', low=1.0)
    max_speed: float = parameter(0.25, 'largest TCP speed', unit='m/s', low=1e-3)
    workspace_lower: tuple[float, ...] = parameter((-0.4, -0.4, -0.4), 'workspace box corner',
                                                   unit='m', length=3)
    workspace_upper: tuple[float, ...] = parameter((0.4, 0.4, 0.4), 'workspace box corner',
                                                   unit='m', length=3)
    initial_position: tuple[float, ...] = parameter((0.0, 0.0, 0.0), 'TCP at start', unit='m',
                                                    length=3)
    force_noise: float = parameter(0.05, 'F/T sensor noise RMS per axis', unit='N', low=0.0)
    force_bias: tuple[float, ...] = parameter((0.0, 0.0, 0.0), 'F/T sensor bias (after taring)',
                                              unit='N', length=3)
    sensor_bandwidth: float = parameter(200.0, 'F/T sensor first-order cut-off', unit='Hz',
                                        low=1.0)
    seed: int = parameter(0, 'seed of the sensor noise', low=0)
    target_timeout: float = parameter(SafetyConfig.link_timeout, 'no target for this long: hold '
                                      'the TCP, then retract', unit='s', low=0.001)


@dataclass(frozen=True)
class FollowerParams(PatientBoundParams, RealtimeParams):
    scheme: str = parameter(Scheme.MODEL.value, 'bilateral scheme', choices=SCHEMES)
    rate: float = parameter(1000.0, 'control rate: a target per tick', unit='Hz', low=1.0,
                            high=10000.0)
    feedback_rate: float = parameter(0.0, 'feedback over the link; 0: 1 kHz for direct and '
                                     'tdpa (a force), 100 Hz for model (a plane)', unit='Hz',
                                     low=0.0, high=10000.0)
    frame_id: str = parameter('base_link', 'the robot\'s base frame')
    scene_file: str = parameter('package://collision_engine/scenes/phantom.yaml',
                                'the patient\'s surface as this site sees it, for the model out '
                                'of contact; empty: only what contact teaches')
    robot_stiffness: float = parameter(1500.0, 'the robot\'s impedance stiffness', unit='N/m',
                                       low=1.0)
    link_timeout: float = parameter(SafetyConfig.link_timeout, 'no command for this long: hold '
                                    'the TCP, then retract', unit='s', low=0.001)
    rejoin_speed: float = parameter(SafetyConfig.rejoin_speed, 'once commands come again, the '
                                    'target goes back to the operator\'s this fast', unit='m/s',
                                    low=1e-4)
    hard_stop_force: float = parameter(EnvelopeConfig.hard_stop, 'a measured force this high '
                                       'holds and retracts the robot until teleop/re_engage',
                                       unit='N', low=0.1)
    drift_rate: float = parameter(2.0, 'tdpa: drift compensation rate', unit='1/s', low=0.0)
    sensor_timeout: float = parameter(0.05, 'no F/T wrench or TCP pose for this long: no force '
                                      'is fed back', unit='s', low=0.001)
    force_noise: float = parameter(EstimatorConfig.force_noise, 'the F/T sensor\'s noise RMS '
                                   'per axis: in a contact, the estimated plane is sent once the '
                                   'fit knows the stiffness through it', unit='N', low=0.0)
    max_command_speed: float = parameter(HAND_SPEED, 'a command asking a speed above this is '
                                         'refused: no hand moves a wand faster', unit='m/s',
                                         low=0.01)
    max_command_age: float = parameter(AdmissionConfig.max_age, 'after a silence this long, a '
                                       'command later than the link\'s best by more than this '
                                       'is dropped (a stalled link\'s backlog)', unit='s',
                                       low=0.001)
    max_stamp_lead: float = parameter(AdmissionConfig.max_lead, 'a command stamped earlier than '
                                      'the link allows by more than this is refused', unit='s',
                                      low=0.001)
    session_timeout: float = parameter(AdmissionConfig.session_timeout, 'the followed '
                                       'operator\'s silence after which another may take over',
                                       unit='s', low=0.01)
    max_command_rate: float = parameter(AdmissionConfig.max_rate, 'commands of the session taken '
                                        'per second at most', unit='Hz', low=1.0)
