"""The patient phantom: a torso-sized closed mesh for the remote site's scene.

Why: the robot's probe needs a body to scan whose surface curves as an abdomen does, with no
patient data to ship. A superellipsoid |x/a|ᵖ + |y/b|ᵖ + |z/c|ᵖ = 1 with p = 3 is a rounded
box: a flattish front, here the abdomen, rounding into the flanks. It is made by pushing the
vertices of an icosphere out along their rays onto that surface; a star-shaped surface keeps the
sphere's connectivity, so the mesh stays closed, free of self-intersections, and wound outward.

``make_phantom`` writes the mesh that ``collision_engine/scenes/phantom.yaml`` loads (its
header cites the tissue's parameters)::

    make_phantom [OUT.stl]
"""

import argparse
from pathlib import Path

import numpy as np

from haptic_contract.checks import finite_number, whole_number

__all__ = ['DEFAULT_OUTPUT', 'main', 'phantom_mesh', 'TORSO_SIZE']

TORSO_SIZE = (0.30, 0.20, 0.15)
"""Full extents (m) along x (head to foot), y (side to side) and z (back to front)."""

DEFAULT_OUTPUT = (Path(__file__).resolve().parents[2]
                  / 'collision_engine' / 'scenes' / 'meshes' / 'phantom.stl')
"""Where the scene expects the mesh, in the source tree."""


def phantom_mesh(size=TORSO_SIZE, *, exponent: float = 3.0, subdivisions: int = 4):
    """Return the phantom as a ``trimesh.Trimesh`` centred at the origin, in metres.

    Parameters
    ----------
    size : (3,) float, m
        Full extents along x, y, z.
    exponent : float
        The superellipsoid's p, >= 2: 2 is an ellipsoid, larger is boxier.
    subdivisions : int
        The icosphere's, >= 1: 20·4ˢ triangles.
    """
    import trimesh  # only here: the rest of the package does not need it

    half = np.asarray(size, dtype=np.float64) / 2.0
    if half.shape != (3,) or not np.all(np.isfinite(half)) or np.any(half <= 0.0):
        raise ValueError(f'phantom size must be 3 finite lengths > 0 m, got {size!r}')
    finite_number(exponent, 'phantom exponent', minimum=2.0)
    sphere = trimesh.creation.icosphere(
        subdivisions=whole_number(subdivisions, 'phantom subdivisions'))
    rays = sphere.vertices
    # The ray u meets the surface at t·u where t^p · Σ|u_i / half_i|^p = 1.
    reach = np.sum(np.abs(rays / half) ** exponent, axis=1) ** (-1.0 / exponent)
    return trimesh.Trimesh(rays * reach[:, None], sphere.faces, process=False)


def main(argv=None) -> None:
    """Write the phantom's STL (default: into the collision engine's scenes)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('output', nargs='?', type=Path, default=DEFAULT_OUTPUT,
                        help=f'the STL file to write (default {DEFAULT_OUTPUT})')
    output = parser.parse_args(argv).output
    phantom_mesh().export(output, file_type='stl')
    print(f'wrote {output}')


if __name__ == '__main__':
    main()
