"""Small scenes for the imaging tests, written as scene files: a block of tissue and what is in it.

The block is 0.1 m on a side, its top at ``TOP`` (0.1 mm above the probe's face at the origin,
so the face is pressed into it), its axes the scene's; a probe with the identity orientation at
the origin looks straight down (-z), its array along y.
"""

from pathlib import Path
import textwrap

import numpy as np

__all__ = ['HALF_TURN_Y', 'MEDIA', 'TOP', 'block_scene', 'straight_down']

TOP = 1e-4  # m
HALF_TURN_Y = '[0.0, 1.5707963267948966, 0.0]'  # rpy: a cylinder's axis (z) along x

MEDIA = {
    # speed m/s, impedance kg/(m^2 s), attenuation dB/(cm MHz), density 1/mm^3, amplitude
    'tissue': (1540.0, 1.63e6, 0.0, 100.0, 0.003),
    'silent': (1540.0, 1.50e6, 0.0, 0.0, 0.0),
    'denser': (1540.0, 2.00e6, 0.0, 0.0, 0.0),
    'blood': (1584.0, 1.61e6, 0.2, 100.0, 0.003 * 10 ** (-35 / 20)),
    'bone': (3476.0, 7.38e6, 6.9, 100.0, 0.003),
    'muscle': (1547.0, 1.65e6, 1.09, 100.0, 0.003),
}


def _medium(name: str, values) -> str:
    c, z, a, d, s = values
    return (f'    {name}: {{speed_of_sound: {c!r}, impedance: {z:.6e}, attenuation: {a!r}, '
            f'scatterer_density: {d!r}, scatterer_amplitude: {s!r}}}\n')


def block_scene(folder: Path, medium: str, structures: str = '', media: dict = None) -> Path:
    """Write a scene: the block filled with ``medium``, then ``structures`` (YAML list items)."""
    media = {**MEDIA, **(media or {})}
    text = textwrap.dedent(f"""\
        objects:
          - name: block
            shape: {{box: {{size: [0.1, 0.1, 0.1]}}}}
            pose: {{position: [0.0, 0.0, {TOP - 0.05!r}]}}
        anatomy:
          media:
        """)
    text += ''.join(_medium(name, values) for name, values in media.items())
    text += '  structures:\n'
    text += f'    - {{name: block, object: block, medium: {medium}}}\n'
    text += textwrap.indent(textwrap.dedent(structures), '    ')
    path = folder / 'scene.yaml'
    path.write_text(text.replace('e+0', 'e+'))  # YAML 1.1 reads 1.6e6 as a string
    return path


def straight_down():
    """Return the probe at the origin, looking down: (position, quaternion)."""
    return np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])
