"""The patient phantom's inner layers and organ, as the meshes ``phantom_anatomy.yaml`` loads.

Why: the ultrasound image needs what lies under the skin, and the phantom ships no patient data.
The layers under the abdomen's front are the phantom's own superellipsoid
(``robot_site.phantom``) made smaller by twice each layer's depth, so that each starts that
deep under the front: fat under 2 mm of skin, muscle under 12 mm of fat, the abdomen's contents
under 10 mm of muscle. The organ (liver-like) is an ellipsoid. The vessel, the cyst and the rib
are primitives in the scene file and need no mesh. ``make_anatomy`` rewrites the meshes, byte for
byte::

    make_anatomy [FOLDER]
"""

import argparse
from pathlib import Path

import numpy as np

__all__ = ['DEFAULT_FOLDER', 'LAYER_DEPTHS', 'ORGAN_SEMI_AXES', 'anatomy_meshes', 'main']

DEFAULT_FOLDER = (Path(__file__).resolve().parents[2]
                  / 'collision_engine' / 'scenes' / 'meshes')
"""Where the scene expects the meshes, in the source tree."""

LAYER_DEPTHS = {'fat': 0.002, 'muscle': 0.014, 'abdomen': 0.024}
"""How deep under the phantom's surface each layer starts, m."""

ORGAN_SEMI_AXES = (0.05, 0.035, 0.022)
"""The organ's half extents along x, y, z, m."""


def anatomy_meshes() -> dict:
    """Return the meshes by file stem (``trimesh.Trimesh``, m).

    The layers are centred at the phantom's centre, the organ at its own.
    """
    import trimesh

    from robot_site.phantom import phantom_mesh, TORSO_SIZE

    meshes = {f'anatomy_{name}': phantom_mesh(np.asarray(TORSO_SIZE) - 2.0 * depth)
              for name, depth in LAYER_DEPTHS.items()}
    organ = trimesh.creation.icosphere(subdivisions=4)
    organ.apply_scale(ORGAN_SEMI_AXES)
    meshes['anatomy_organ'] = organ
    return meshes


def main(argv=None) -> None:
    """Write the anatomy's STL files (default: into the collision engine's scenes)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('folder', nargs='?', type=Path, default=DEFAULT_FOLDER,
                        help=f'where to write them (default {DEFAULT_FOLDER})')
    folder = parser.parse_args(argv).folder
    for stem, mesh in anatomy_meshes().items():
        mesh.export(folder / f'{stem}.stl', file_type='stl')
        print(f'wrote {folder / stem}.stl')


if __name__ == '__main__':
    main()
