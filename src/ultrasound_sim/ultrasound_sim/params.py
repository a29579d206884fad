"""The imaging node's ROS parameters: the probe and scanner settings, and where the image goes.

The probe's fields are ``ProbeSettings``'s, with its defaults; ``ProbeSettings`` checks them, so
that a bad one (an unknown probe type, a zero depth, more scanlines than pixels across) stops
the node at start with the field named.
"""

from dataclasses import dataclass, fields

from haptic_util.parameters import parameter
from ultrasound_sim.settings import ProbeSettings

__all__ = ['ProbeImagerParams']

_PROBE = ProbeSettings()


@dataclass(frozen=True)
class ProbeImagerParams:
    frame_rate: float = parameter(30.0, 'frames a second, each from the newest TCP pose',
                                  unit='Hz', low=0.1, high=200.0)
    scene_file: str = parameter('package://collision_engine/scenes/phantom_anatomy.yaml',
                                'the patient: its surfaces (the contact face), its anatomy '
                                '(what the image sees) and the probe\'s mount (its tool)')
    frame_id: str = parameter('base_link', 'the TCP pose\'s frame, which the scene is in')
    probe_frame: str = parameter('ultrasound_probe', 'the image\'s frame: the centre of the '
                                 'probe\'s face, the array along y, the beams along -z')
    niceness: int = parameter(5, 'added to the niceness of the thread that makes the frames, '
                              'so that the site\'s 1 kHz loops go first for the cores',
                              low=0, high=19)
    idle: bool = parameter(False, 'the thread that makes the frames runs only on what every '
                           'other process leaves of the cores (SCHED_IDLE): on a machine of its '
                           'own, the loops preempt it at once; on a busy one, it may starve')
    probe_type: str = parameter(_PROBE.probe_type, 'linear or convex')
    centre_frequency: float = parameter(_PROBE.centre_frequency, 'transmit centre frequency',
                                        unit='Hz')
    bandwidth: float = parameter(_PROBE.bandwidth, 'pulse-echo -6 dB bandwidth, a fraction '
                                 'of the centre frequency')
    cycles: float = parameter(_PROBE.cycles, 'cycles of the transmitted burst')
    depth: float = parameter(_PROBE.depth, 'how deep each scanline reaches', unit='m')
    width: float = parameter(_PROBE.width, 'linear: the field\'s width', unit='m')
    angle: float = parameter(_PROBE.angle, 'convex: the field of view', unit='rad')
    radius: float = parameter(_PROBE.radius, 'convex: the array\'s radius of curvature',
                              unit='m')
    scanlines: int = parameter(_PROBE.scanlines, 'scanlines across the field, at most '
                               'image_width')
    samples: int = parameter(_PROBE.samples, 'samples along each scanline')
    image_width: int = parameter(_PROBE.image_width, 'the image\'s width', unit='px')
    image_height: int = parameter(_PROBE.image_height, 'the image\'s height', unit='px')
    f_number: float = parameter(_PROBE.f_number, 'depth over active aperture of the focusing')
    slice_thickness: float = parameter(_PROBE.slice_thickness, 'the beam\'s elevation width',
                                       unit='m')
    gain: float = parameter(_PROBE.gain, 'added to every echo level', unit='dB')
    tgc: tuple[float, ...] = parameter(_PROBE.tgc, 'time-gain compensation: gains at depths '
                                       'spread evenly from the face to depth', unit='dB')
    dynamic_range: float = parameter(_PROBE.dynamic_range, 'echo levels from black to white',
                                     unit='dB')
    speed_of_sound: float = parameter(_PROBE.speed_of_sound, 'what the scanner assumes',
                                      unit='m/s')
    coupling_gap: float = parameter(_PROBE.coupling_gap, 'a scanline sees when its element is '
                                    'at most this far above the skin', unit='m')

    def settings(self) -> ProbeSettings:
        """Return the probe's settings; raise ValueError naming a bad field."""
        return ProbeSettings(**{field.name: getattr(self, field.name)
                                for field in fields(ProbeSettings)})
