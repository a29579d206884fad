"""The probe's geometry and the scanner's settings: one frozen, checked value for the model.

The imaging node fills it from its parameters; the model never reads a parameter. Every field
is checked when the value is made, and a bad one raises a ``ValueError`` that names the field,
so that a wrong setting is refused before a frame is made, never turned into a wrong image.

The probe frame (REP-103, right-handed): origin at the centre of the array's face (its apex for
a convex array), y along the array (scanline 0 at -y), x across it (elevation), z out of the
face away from the patient: the beams go along -z. The collision scene's probe tool has its face
at the tip, its long side along y: with no mount between them the two frames are one.
"""

from dataclasses import dataclass
import math

from haptic_contract.checks import finite_components, finite_number, whole_number

__all__ = ['LINEAR', 'CONVEX', 'PROBE_TYPES', 'ProbeSettings']

LINEAR = 'linear'
CONVEX = 'convex'
PROBE_TYPES = (LINEAR, CONVEX)


def _require(condition: bool, field: str, message: str, value) -> None:
    if not condition:
        raise ValueError(f'{field} {message}, got {value!r}')


def _check(settings, name: str, check, **bounds) -> None:
    """Check field ``name`` with a contract check, and keep what it returns (a float, an int)."""
    object.__setattr__(settings, name, check(getattr(settings, name), name, **bounds))


@dataclass(frozen=True)
class ProbeSettings:
    """A probe and its scanner settings (SI units, but decibels where scanners use them).

    Attributes
    ----------
    probe_type : str
        ``'linear'`` (parallel scanlines across ``width``) or ``'convex'`` (a fan of
        ``angle`` from an arc of ``radius``).
    centre_frequency : float, Hz
    bandwidth : float
        The transducer's pulse-echo -6 dB bandwidth as a fraction of the centre frequency.
    cycles : float
        Cycles of the transmitted burst.
    depth : float, m
        How deep each scanline reaches from the face.
    width : float, m
        A linear array's field width (its active aperture).
    angle : float, rad
        A convex array's field of view.
    radius : float, m
        A convex array's radius of curvature.
    scanlines : int
        Scanlines across the field, no more than ``image_width``.
    samples : int
        Samples along each scanline.
    image_width, image_height : int, px
        The scan-converted image.
    f_number : float
        Depth over active aperture of the transmit and receive focusing.
    slice_thickness : float, m
        The beam's elevation width: with the in-plane cell, the volume whose scatterers make one
        speckle grain.
    gain : float, dB
        Added to every echo level (20 dB: the phantom's tissues in the middle greys).
    tgc : tuple of float, dB
        Time-gain compensation: gains at depths spread evenly from the face to ``depth``,
        interpolated between (all zero: off).
    dynamic_range : float, dB
        The span of echo levels from black to white.
    speed_of_sound : float, m/s
        The speed the scanner assumes to turn echo time into depth.
    coupling_gap : float, m
        A scanline is coupled to the skin when its element is at most this far above it (the
        gel's film).
    """

    probe_type: str = LINEAR
    centre_frequency: float = 5.0e6
    bandwidth: float = 0.7
    cycles: float = 2.0
    depth: float = 0.06
    width: float = 0.0384
    angle: float = math.radians(60.0)
    radius: float = 0.05
    scanlines: int = 128
    samples: int = 512
    image_width: int = 256
    image_height: int = 256
    f_number: float = 1.5
    slice_thickness: float = 1.0e-3
    gain: float = 20.0
    tgc: tuple = (0.0,) * 8
    dynamic_range: float = 60.0
    speed_of_sound: float = 1540.0
    coupling_gap: float = 1.0e-4

    def __post_init__(self) -> None:
        _require(self.probe_type in PROBE_TYPES, 'probe_type',
                 f'must be one of {", ".join(PROBE_TYPES)}', self.probe_type)
        positive = ('centre_frequency', 'bandwidth', 'cycles', 'depth', 'width', 'angle',
                    'radius', 'f_number', 'slice_thickness', 'dynamic_range', 'speed_of_sound')
        for name in positive:
            _check(self, name, finite_number, minimum=0.0, strict=True)
        _check(self, 'gain', finite_number)
        _check(self, 'coupling_gap', finite_number, minimum=0.0)
        _require(self.bandwidth < 2.0, 'bandwidth', 'must be below 2 (a fraction of the centre '
                 'frequency)', self.bandwidth)
        _require(self.angle < math.pi, 'angle', 'must be below pi rad', self.angle)
        for name in ('scanlines', 'samples', 'image_width', 'image_height'):
            _check(self, name, whole_number, minimum=2)
        _require(self.scanlines <= self.image_width, 'scanlines',
                 f'must be at most image_width ({self.image_width}): more scanlines than '
                 'pixels across cannot be shown', self.scanlines)
        _require(isinstance(self.tgc, tuple) and len(self.tgc) >= 1, 'tgc',
                 'must be a tuple of at least one gain (dB)', self.tgc)
        _check(self, 'tgc', lambda gains, name: finite_components(gains, len(gains), name))

    @property
    def wavelength(self) -> float:
        """The wavelength at the centre frequency, m."""
        return self.speed_of_sound / self.centre_frequency

    @property
    def sample_spacing(self) -> float:
        """The depth between samples along a scanline, m."""
        return self.depth / self.samples
