"""The wand driver's ROS parameters, in one place (see config/haptic_wand_driver.yaml)."""
from dataclasses import dataclass

from haptic_contract.shared_defaults import DEFAULT_SCENE, DEVICE_DAMPING, FORCE_LIMIT, \
    LOOP_RATE
from haptic_util.parameters import parameter, RealtimeParams
from haptic_wand_driver.simulated import DEVICE_MASS, SERVO_RATE, TORQUE_LIMIT

__all__ = ['WandDriverParams']


@dataclass(frozen=True)
class WandDriverParams(RealtimeParams):
    device: str = parameter('simulated', 'device backend: simulated (its hand from the '
                            'simulated_operator package), replay, or one a package names in the '
                            'entry point group haptic_wand_driver.wands')
    rate: float = parameter(LOOP_RATE, 'pose publishing rate', unit='Hz', low=1.0, high=10000.0)
    frame_id: str = parameter('world', 'frame of the published pose, twist and expected wrench')
    experiment: str = parameter('cuboid', 'simulated operator script: cuboid, cylinder, hand, '
                                'hold, or a waypoint file (.yaml/.csv)')
    scene_file: str = parameter(DEFAULT_SCENE, 'scene the scripted operator taps (simulated '
                                'device only)')
    replay_file: str = parameter('', 'recording to replay (device: replay): a bag or a CSV')
    replay_loop: bool = parameter(False, 'start the replay over at its end')
    duration: float = parameter(0.0, 'run the experiment this long, then exit (0: forever)',
                                unit='s', low=0.0)
    wrench_timeout: float = parameter(0.010, 'a wrench older than this is stale: zero force',
                                      unit='s', low=0.0005, high=1.0)
    hold_while_late: float = parameter(0.0, 'while the next pose is late (a busy machine), the '
                                       'answer to the newest pose holds until it is sent, at '
                                       'most this long after its pose (at most the answer\'s '
                                       'lifetime, 0 say: that lifetime only)', unit='s',
                                       low=0.0, high=1.0)
    rendering: str = parameter('local', 'local: the device renders the contact model at its servo '
                               'rate; remote: it applies the wrench as it arrives',
                               choices=('local', 'remote'))
    contact_damping_ratio: float = parameter(1.0, 'local rendering: damping ratio of a contact '
                                             'on the device\'s mass, added along the normal '
                                             '(0: the material\'s alone)', low=0.0, high=5.0)
    model_step_rate: float = parameter(0.0, 'local rendering: a new contact model eases in at '
                                       'most this fast (spring push; 0: at once)', unit='N/s',
                                       low=0.0)
    servo_rate: float = parameter(SERVO_RATE, 'simulated device: its servo rate (the dynamics '
                                  'substep)', unit='Hz', low=100.0, high=100000.0)
    force_limit: float = parameter(FORCE_LIMIT, 'device force limit (saturation)', unit='N',
                                   low=0.0)
    passivity: bool = parameter(True, 'passivity observer and controller at the device port: '
                                'removes the energy the loop delay makes a stiff wall return')
    passivity_max_damping: float = parameter(50.0, 'largest damping it adds (keep below '
                                             'device mass / servo period)', unit='N*s/m',
                                             low=0.0)
    torque_limit: float = parameter(TORQUE_LIMIT, 'device torque limit (saturation)', unit='N*m',
                                    low=0.0)
    device_mass: float = parameter(DEVICE_MASS, 'simulated apparent mass per axis', unit='kg',
                                   low=1e-4)
    device_damping: float = parameter(DEVICE_DAMPING, 'simulated physical damping per axis',
                                      unit='N*s/m', low=0.0)
    hand_stiffness: float = parameter(50.0, 'simulated operator hand stiffness', unit='N/m',
                                      low=0.0)
    hand_damping: float = parameter(3.5, 'simulated operator hand damping', unit='N*s/m',
                                    low=0.0)
    min_subscribers: int = parameter(1, 'start only once wand/pose has this many matched '
                                     'subscribers', low=0)
    wait_for_wrench: bool = parameter(True, 'start only once an answer (a wrench, or the model '
                                      'when rendering locally) came back for a pose (the loop '
                                      'is closed end to end); false: open loop (replay)')
    wait_for_recorder: bool = parameter(False, 'start only once recorder/ready says every '
                                        'stream is being recorded')
    stats_file: str = parameter('', 'write round-trip latencies (.npz) here on exit')
