"""The scene's anatomy as the acoustic model needs it: triangles in the scene frame, and media.

A scene file's ``anatomy`` section (``collision_engine.scene_file``) lists media with their
acoustic properties and structures filled with them, painted in order: where structures overlap,
the later one's medium is the one there. Every structure becomes a closed triangle mesh in the
scene frame (a mesh file as it is, a primitive tessellated finely enough that its cut by the
scan plane is off its true outline by about 3e-4 of its size); all meshes go into one array,
each triangle tagged with its structure. The anatomy is fixed to the scene frame, and so is
the scatterer field: the speckle stays with the tissue as the probe moves.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from collision_engine.scene_file import (AnatomySpec, BoxSpec, CapsuleSpec, CylinderSpec,
                                         MediumSpec, read_scene, SceneSpec, SphereSpec)

__all__ = ['Anatomy', 'MEDIA_COLUMNS', 'load_anatomy']

MEDIA_COLUMNS = ('speed_of_sound', 'impedance', 'attenuation', 'backscatter')
"""The columns of ``Anatomy.media``: m/s, kg/(m^2 s), dB/(cm MHz), and the backscatter
amplitude a sqrt(density), with density per mm^3."""

_ROUND_SECTIONS = 128  # a circle's segments: off by r (1 - cos(pi / 128)) = 3e-4 r
_SPHERE_SUBDIVISIONS = 5  # icosphere edges of about r / 40: off by about 3e-4 r


@dataclass(frozen=True, eq=False)
class Anatomy:
    """Structures as one triangle soup in the scene frame, and their media.

    Attributes
    ----------
    vertices : (n, 3) float64, m, scene frame
    triangles : (m, 3) int64
        Indices into ``vertices``.
    owner : (m,) int64
        Each triangle's structure, in painting order.
    structure_medium : (structures,) int64
        Each structure's row of ``media``.
    media : (media, 4) float64
        ``MEDIA_COLUMNS``.
    names : tuple of str
        The structures', in order.
    medium_names : tuple of str
        The media's, in row order.
    frame_id : str
        The scene frame.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    owner: np.ndarray
    structure_medium: np.ndarray
    media: np.ndarray
    names: tuple
    medium_names: tuple
    frame_id: str


def _mesh(shape):
    """Return a closed trimesh of a scene file's shape, in the shape's own frame."""
    import trimesh

    if isinstance(shape, BoxSpec):
        return trimesh.creation.box(extents=shape.size)
    if isinstance(shape, SphereSpec):
        return trimesh.creation.icosphere(subdivisions=_SPHERE_SUBDIVISIONS, radius=shape.radius)
    if isinstance(shape, CylinderSpec):
        return trimesh.creation.cylinder(radius=shape.radius, height=shape.height,
                                         sections=_ROUND_SECTIONS)
    if isinstance(shape, CapsuleSpec):  # convex: the hull of its two end spheres, closed
        ball = trimesh.creation.icosphere(subdivisions=_SPHERE_SUBDIVISIONS, radius=shape.radius)
        ends = [ball.vertices + [0.0, 0.0, z] for z in (-0.5 * shape.length, 0.5 * shape.length)]
        return trimesh.convex.convex_hull(np.vstack(ends))
    mesh = trimesh.load_mesh(Path(shape.file), process=True)
    mesh.apply_scale(shape.scale)
    return mesh


def _medium_row(medium: MediumSpec) -> list:
    return [medium.speed_of_sound, medium.impedance, medium.attenuation,
            medium.scatterer_amplitude * np.sqrt(medium.scatterer_density)]


def _from_spec(anatomy: AnatomySpec, frame_id: str) -> Anatomy:
    medium_names = tuple(anatomy.media)
    vertices, triangles, owner = [], [], []
    offset = 0
    for index, structure in enumerate(anatomy.structures):
        mesh = _mesh(structure.shape)
        placed = structure.pose.to_world(np.asarray(mesh.vertices, dtype=np.float64))
        vertices.append(placed)
        triangles.append(np.asarray(mesh.faces, dtype=np.int64) + offset)
        owner.append(np.full(len(mesh.faces), index, dtype=np.int64))
        offset += len(placed)
    return Anatomy(
        vertices=np.ascontiguousarray(np.vstack(vertices)),
        triangles=np.ascontiguousarray(np.vstack(triangles)),
        owner=np.concatenate(owner),
        structure_medium=np.array([medium_names.index(s.medium) for s in anatomy.structures],
                                  dtype=np.int64),
        media=np.array([_medium_row(anatomy.media[name]) for name in medium_names]),
        names=tuple(s.name for s in anatomy.structures),
        medium_names=medium_names,
        frame_id=frame_id)


def load_anatomy(scene) -> Anatomy:
    """Build the anatomy of a scene file.

    Parameters
    ----------
    scene : str, pathlib.Path or SceneSpec
        The scene file (or it read by ``read_scene``).

    Returns
    -------
    Anatomy

    Raises
    ------
    ValueError
        ``SceneError`` for a bad scene file; a ``ValueError`` naming the file and
        ``anatomy`` if the scene has no acoustic properties.
    """
    spec = scene if isinstance(scene, SceneSpec) else read_scene(scene)
    if spec.anatomy is None:
        raise ValueError(f'{spec.path}: anatomy: missing: the scene has no acoustic properties '
                         '(media and structures) to image')
    return _from_spec(spec.anatomy, spec.frame_id)
