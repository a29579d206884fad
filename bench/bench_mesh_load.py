"""Load time of the shipped meshes, and the self-intersection check beside FCL's self-collision.

    .venv/bin/python bench/bench_mesh_load.py [--rounds 5]

For each shipped mesh: ``load_mesh`` with and without the self-intersection check (parsing,
welding and every validation), the compiled check alone (``self_intersection``: an AABB tree and
exact-form triangle pair tests), and python-fcl colliding the mesh with itself, each triangle
shrunk by 1e-6 so that neighbours do not touch (how ``load_mesh`` checked before, and only with
FCL cross-validation on). Medians over ``rounds`` in ms, after one warm-up round (numba's
compile or cache load), with the ratio of our check to FCL's measured in the same run.
"""

import argparse
from pathlib import Path
import time

from bench import machine
import numpy as np

from collision_engine.mesh_io import load_mesh
from collision_engine.self_intersection import self_intersections

MESHES = Path(__file__).resolve().parents[1] / 'src' / 'collision_engine' / 'scenes' / 'meshes'
SHIPPED = {'hand.stl': 0.001, 'cylinder.stl': 1.0, 'cuboid.stl': 1.0}
SHRINK = 1e-6


def fcl_self_collision(vertices: np.ndarray, faces: np.ndarray) -> int:
    """Count pairs of triangles FCL finds touching, each shrunk toward its centroid."""
    import fcl

    corners = vertices[faces]
    centroid = corners.mean(axis=1, keepdims=True)
    shrunk = (centroid + (1.0 - SHRINK) * (corners - centroid)).reshape(-1, 3)
    model = fcl.BVHModel()
    model.beginModel(len(shrunk), len(faces))
    model.addSubModel(shrunk, np.arange(len(shrunk)).reshape(-1, 3))
    model.endModel()
    body = fcl.CollisionObject(model, fcl.Transform())
    request = fcl.CollisionRequest(num_max_contacts=len(faces) + 1000, enable_contact=True)
    result = fcl.CollisionResult()
    fcl.collide(body, body, request, result)
    return len({tuple(sorted((c.b1, c.b2))) for c in result.contacts if c.b1 != c.b2})


def median_ms(function, rounds: int) -> float:
    """Median wall time of ``function()`` in ms, after one untimed call."""
    function()
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        function()
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times))


def main(argv=None) -> None:
    """Print the machine and one line per shipped mesh."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--rounds', type=int, default=5)
    args = parser.parse_args(argv)
    print('machine:', machine.line('numpy', 'numba', 'trimesh', 'python-fcl'))
    print(f'{"mesh":13s} {"faces":>6s} {"load ms":>8s} {"unchecked":>9s} {"check ms":>9s} '
          f'{"fcl ms":>8s} {"/ fcl":>6s} {"pairs":>5s} {"fcl pairs":>9s}')
    for name, scale in SHIPPED.items():
        path = MESHES / name
        mesh = load_mesh(path, scale=scale, check_self_intersection=False)
        checked = median_ms(lambda: load_mesh(path, scale=scale), args.rounds)
        unchecked = median_ms(
            lambda: load_mesh(path, scale=scale, check_self_intersection=False), args.rounds)
        ours = median_ms(lambda: self_intersections(mesh.vertices, mesh.faces), args.rounds)
        peer = median_ms(lambda: fcl_self_collision(mesh.vertices, mesh.faces), args.rounds)
        pairs = self_intersections(mesh.vertices, mesh.faces)[0]
        fcl_pairs = fcl_self_collision(mesh.vertices, mesh.faces)
        print(f'{name:13s} {len(mesh.faces):6d} {checked:8.1f} {unchecked:9.1f} {ours:9.2f} '
              f'{peer:8.2f} {ours / peer:6.2f} {pairs:5d} {fcl_pairs:9d}')


if __name__ == '__main__':
    main()
