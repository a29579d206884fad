"""How far a contact model's plane is from the surface once the tip has moved on it.

    .venv/bin/python bench/model_error.py [--contacts 2000] [--moves 0.1 0.5 1 2] [--depth 1]

A plane is exact at its point only. For contacts ``--depth`` mm deep at random places on the
shipped cylinder (curvature radius 25 mm) and hand meshes, the plane the force renderer sends
(``SpringDamper.planes``: the tangent plane at the closest point) is compared, after the tip moved
``s`` mm in a random direction, with the exact signed distance there (the engine's exact query):
the depth error, which the normal law turns into a force error K times as large. Per object and
s: median, p99 and max of |depth error| in µm, and the bound for a cylinder of radius R,
s²/(2(R - d)), beside them. ``valid_radius`` (2 mm by default) bounds s.
"""
import argparse

from bench import machine
import numpy as np

from collision_engine import load_scene
from force_renderer.contact import Contact
from force_renderer.spring_damper import SpringDamper

__all__ = ['depth_errors', 'main']

SCENES = {'cylinder': 'src/collision_engine/scenes/cylinder.yaml',
          'hand': 'src/collision_engine/scenes/hand.yaml'}
CYLINDER_RADIUS = 0.025  # [m]


def contact_points(scene, count: int, depth: float, rng) -> list:
    """Tips ``depth`` inside the surface at random places: surface points pushed in."""
    obj = scene.objects[0]
    lower, upper = (np.asarray(b) for b in _bounds(scene))
    tips = []
    while len(tips) < count:
        result = scene.query(rng.uniform(lower, upper))
        tip = result.point - depth * result.normal
        inside = scene.query(tip)
        if abs(inside.distance + depth) < 1e-9 and inside.object == obj.name:
            tips.append(tip)
    return tips


def _bounds(scene):
    centre, radius = scene.objects[0].shape.bounding_sphere()
    world = scene.objects[0].pose.to_world(centre)
    return world - 1.2 * radius, world + 1.2 * radius


def depth_errors(scene, tips, move: float, rng) -> np.ndarray:
    """|plane depth - exact depth| after moving each tip by ``move`` m in a random direction."""
    law = SpringDamper(1.0, 0.0)
    errors = []
    for tip in tips:
        result = scene.query(tip)
        contact = Contact(result.distance, result.point, result.normal, tip)
        (point, normal, _, _), = law.planes(contact)
        direction = rng.normal(size=3)
        moved = tip + move * direction / np.linalg.norm(direction)
        plane_depth = float(np.dot(normal, np.asarray(point) - moved))
        errors.append(abs(plane_depth + scene.query(moved).distance))
    return np.array(errors)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--contacts', type=int, default=2000)
    parser.add_argument('--moves', nargs='+', type=float, default=[0.1, 0.5, 1.0, 2.0],
                        help='tip displacements, mm')
    parser.add_argument('--depth', type=float, default=1.0, help='contact depth, mm')
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numpy")}')
    depth = 1e-3 * args.depth
    print(f'{"object":<9} {"s mm":>5} {"median um":>10} {"p99 um":>8} {"max um":>8} '
          f'{"cylinder bound um":>17}')
    rng = np.random.default_rng(0)
    for name, path in SCENES.items():
        scene = load_scene(path)
        tips = contact_points(scene, args.contacts, depth, rng)
        for move in args.moves:
            s = 1e-3 * move
            errors = 1e6 * depth_errors(scene, tips, s, rng)
            bound = 1e6 * s * s / (2.0 * (CYLINDER_RADIUS - depth))
            print(f'{name:<9} {move:5.1f} {np.median(errors):10.2f} '
                  f'{np.percentile(errors, 99):8.2f} {errors.max():8.2f} {bound:17.2f}',
                  flush=True)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
