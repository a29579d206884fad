#!/usr/bin/env python3
"""Make the shipped meshes: a non-convex hand, and the paper's cylinder and cuboid.

A maintainer's script, not run by CI or at run time; its outputs are committed. It is
deterministic (no randomness, fixed grids), so re-running it rewrites the same bytes with the same
library versions. It needs scikit-image for marching cubes, which nothing shipped or tested
imports (`pip install scikit-image` into the venv to run it).

Outputs, in src/collision_engine/scenes/meshes/:
- hand.stl: a right hand, back (dorsal) side up (+z), fingers along +y, thumb toward -x, in
  MILLIMETRES (as a CT export would be; scenes load it with scale 0.001), bounding box centred at
  the origin: 187 mm long, 130 mm wide with the thumb (palm 83 mm at the knuckles), palm 28 mm
  thick, 5650 vertices. A smooth union of a palm and capsule finger bones, meshed by marching
  cubes; the fingers are 6-11 mm apart halfway along their first bones.
- cylinder.stl: r = 0.025 m, h = 0.1 m, axis z, centred, 152 triangles (456 vertex rows), metres.
- cuboid.stl: 0.1 x 0.1 x 0.2 m (x, y, z), centred, 12 triangles (36 vertex rows), metres.

Every mesh is checked after a round trip through its binary STL (float32 coordinates, vertices
welded on exact coordinates): one watertight body, consistent outward winding, no zero-area face.
"""

from pathlib import Path

import numpy as np
from skimage.measure import marching_cubes
import trimesh

MESH_DIR = Path(__file__).resolve().parents[1] / 'src' / 'collision_engine' / 'scenes' / 'meshes'

# Hand, in millimetres. Palm: a rounded slab from the wrist (y = 0) to the knuckles (y ~ 100).
PALM_CENTRE = np.array([0.0, 50.0, 0.0])
PALM_HALF_SIZE = np.array([44.0, 50.0, 14.0])   # 88 mm wide (83 at the knuckles), 28 thick
PALM_ROUNDING = 12.0
DORSAL_ARCH = 0.003                             # 1/mm: the back drops 5 mm at the sides
WRIST_TAPER = 0.25                              # the palm is 88 / 1.25 = 70 mm wide at the wrist
# Fingers: (knuckle x, knuckle y, bone lengths from knuckle to tip-sphere centre, radius, spread).
FINGERS = (
    (-29.0, 93.0, (40.0, 24.0, 14.0), 8.5, -7.0),   # index
    (-9.5, 96.0, (44.0, 27.0, 15.0), 8.7, 0.0),     # middle
    (10.0, 93.0, (41.0, 26.0, 14.0), 8.2, 7.0),     # ring
    (29.0, 85.0, (33.0, 19.0, 12.0), 7.2, 15.0),    # little
)
FINGER_FLEXION = 7.0                            # degrees, toward the palm (-z) at each joint
THUMB = ((-30.0, 20.0, -4.0), (-50.0, 45.0, -9.0), (-63.0, 70.0, -13.0), (-70.0, 90.0, -15.0))
THUMB_RADII = (12.0, 10.0, 9.0)
FINGER_TO_PALM_BLEND = 7.0                      # mm: smooth-union radius (web and knuckle fillets)
GRID_STEP = 3.1                                 # mm: marching-cubes voxel size
SMOOTHING_ITERATIONS = 20                       # Taubin: removes marching-cubes slivers


def rounded_box_sdf(points: np.ndarray, half_size: np.ndarray, rounding: float) -> np.ndarray:
    """Signed distance to a box with rounded edges (outer half extents `half_size`)."""
    excess = np.abs(points) - (half_size - rounding)
    outside = np.linalg.norm(np.maximum(excess, 0.0), axis=-1)
    return outside + np.minimum(excess.max(axis=-1), 0.0) - rounding


def capsule_sdf(points: np.ndarray, start: np.ndarray, end: np.ndarray,
                radius: float) -> np.ndarray:
    """Signed distance to the capsule around segment start-end."""
    axis = end - start
    along = np.clip(((points - start) @ axis) / (axis @ axis), 0.0, 1.0)
    return np.linalg.norm(points - start - along[..., None] * axis, axis=-1) - radius


def smooth_union(a: np.ndarray, b: np.ndarray, blend: float) -> np.ndarray:
    """Polynomial smooth minimum (Quilez): min(a, b) with a fillet of size `blend`."""
    h = np.clip(0.5 + 0.5 * (b - a) / blend, 0.0, 1.0)
    return b + (a - b) * h - blend * h * (1.0 - h)


def finger_joints(knuckle_x: float, knuckle_y: float, bones: tuple, spread: float) -> np.ndarray:
    """Joint centres from knuckle to tip, each bone flexed a little more toward the palm."""
    z_knuckle = -DORSAL_ARCH * knuckle_x ** 2
    joints = [np.array([knuckle_x, knuckle_y, z_knuckle])]
    heading = np.radians(spread)
    for index, length in enumerate(bones):
        flexion = np.radians(FINGER_FLEXION * (index + 1))
        direction = np.array([np.sin(heading) * np.cos(flexion),
                              np.cos(heading) * np.cos(flexion), -np.sin(flexion)])
        joints.append(joints[-1] + length * direction)
    return np.array(joints)


def hand_sdf(points: np.ndarray) -> np.ndarray:
    """Approximate signed distance to the hand (mm); exact only on its zero level set's side."""
    palm_frame = points - PALM_CENTRE
    palm_frame[..., 2] += DORSAL_ARCH * points[..., 0] ** 2
    towards_wrist = np.clip(0.5 - palm_frame[..., 1] / (2.0 * PALM_HALF_SIZE[1]), 0.0, 1.0)
    palm_frame[..., 0] *= 1.0 + WRIST_TAPER * towards_wrist
    palm = rounded_box_sdf(palm_frame, PALM_HALF_SIZE, PALM_ROUNDING)
    bones = []
    for knuckle_x, knuckle_y, lengths, radius, spread in FINGERS:
        joints = finger_joints(knuckle_x, knuckle_y, lengths, spread)
        bones += [capsule_sdf(points, joints[i], joints[i + 1], radius * (1.0 - 0.05 * i))
                  for i in range(len(lengths))]
    thumb = np.array(THUMB)
    bones += [capsule_sdf(points, thumb[i], thumb[i + 1], radius)
              for i, radius in enumerate(THUMB_RADII)]
    return smooth_union(palm, np.min(bones, axis=0), FINGER_TO_PALM_BLEND)


def make_hand() -> trimesh.Trimesh:
    """Mesh the hand's zero level set on a grid padded so the surface is closed."""
    low = np.array([-95.0, -15.0, -35.0])
    high = np.array([60.0, 200.0, 30.0])
    # An offset that no vertex of the surface is likely to hit keeps triangles non-degenerate.
    axes = [np.arange(lo, hi, GRID_STEP) + 0.1234 for lo, hi in zip(low, high)]
    grid = np.stack(np.meshgrid(*axes, indexing='ij'), axis=-1)
    field = hand_sdf(grid)
    assert np.all(field[[0, -1]] > 0) and np.all(field[:, [0, -1]] > 0), 'grid too small'
    assert np.all(field[:, :, [0, -1]] > 0), 'grid too small'
    vertices, faces, _, _ = marching_cubes(field, level=0.0, spacing=(GRID_STEP,) * 3,
                                           gradient_direction='descent', allow_degenerate=False)
    hand = trimesh.Trimesh(vertices + [axis[0] for axis in axes], faces, process=True)
    # Marching cubes leaves slivers (angles down to 0.01 deg) where the surface passes near a
    # grid node; Taubin smoothing evens them out (least angle ~20 deg) and keeps the volume.
    trimesh.smoothing.filter_taubin(hand, iterations=SMOOTHING_ITERATIONS)
    hand.apply_translation(-hand.bounds.mean(axis=0))
    return hand


def make_cylinder(radius: float = 0.025, height: float = 0.1,
                  segments: int = 38) -> trimesh.Trimesh:
    """Capped cylinder, axis z: 2 * segments side triangles and a centre fan on each cap."""
    return trimesh.creation.cylinder(radius=radius, height=height, sections=segments)


def make_cuboid(size: tuple = (0.1, 0.1, 0.2)) -> trimesh.Trimesh:
    """Axis-aligned box centred at the origin, two triangles a face."""
    return trimesh.creation.box(extents=size)


def write_checked_stl(mesh: trimesh.Trimesh, path: Path) -> trimesh.Trimesh:
    """Write `mesh` as binary STL, read it back welded on exact coordinates, and check it."""
    path.write_bytes(trimesh.exchange.stl.export_stl(mesh))
    loaded = trimesh.load_mesh(path, process=False)
    loaded.merge_vertices(digits_vertex=None, merge_tex=True, merge_norm=True)
    corners = loaded.triangles
    doubled_area = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0],
                                           corners[:, 2] - corners[:, 0]), axis=1)
    problems = {
        'not watertight': not loaded.is_watertight,
        'inconsistent winding': not loaded.is_winding_consistent,
        'inward winding': loaded.volume <= 0.0,
        'more than one body': loaded.body_count != 1,
        'zero-area faces': np.any(doubled_area == 0.0),
    }
    found = [name for name, bad in problems.items() if bad]
    if found:
        raise RuntimeError(f'{path}: {", ".join(found)}')
    extent = loaded.extents
    print(f'{path.name}: {len(loaded.vertices)} vertices, {len(loaded.faces)} triangles '
          f'({3 * len(loaded.faces)} vertex rows), extents {np.round(extent, 6).tolist()}, '
          f'volume {loaded.volume:.6g}, convex {loaded.is_convex}, '
          f'least face area {0.5 * doubled_area.min():.3g}')
    return loaded


def main() -> None:
    """Write the three meshes, checking each."""
    MESH_DIR.mkdir(parents=True, exist_ok=True)
    write_checked_stl(make_hand(), MESH_DIR / 'hand.stl')
    write_checked_stl(make_cylinder(), MESH_DIR / 'cylinder.stl')
    write_checked_stl(make_cuboid(), MESH_DIR / 'cuboid.stl')


if __name__ == '__main__':
    main()
