"""The report: the paper's three experiments, reproduced over ROS 2, measured against exact truth.

    .venv/bin/python bench/report.py [--demo-dir build/demo] [--out report]
                                     [--skip loop timing sweep stiffwall extreme] [--quick]

Reads the bags ``demo`` recorded (the simulated wand tapping the hand, the cylinder and the
cuboid over ROS 2), computes the exact signed distance and outward normal along each recorded
tip trajectory (``tests/ground_truth.py``: analytic for the box and the cylinder, brute force
with a winding-number sign for the hand; it shares no code with the engine), replays the
paper's own collision code (``paper_method.py``, on the paper's STL objects) along the same
trajectories, and writes ``README.md`` with PNG figures into ``--out``: the paper's Figures
1-3 and Tables 1, 2, 4 with its reported values beside ours, error against run time for every
method, our GJK's tolerance trade-off, the loop latency at 0.5, 1 and 2 kHz, the stiffness
sweep, the extreme-geometry table, message counts, and the machine. Every number of ours is
computed by the run; the paper's are typed in from it (``PAPER``) and labelled as such.

``--skip`` leaves out slow stages while iterating (their sections then say so); ``--quick``
uses fewer points and shorter loop runs.
"""

import argparse
from dataclasses import dataclass
import datetime
from importlib.metadata import PackageNotFoundError, version
import math
import os
from pathlib import Path
import platform
import subprocess
import sys
import time

import machine as bench_machine
import numpy as np

import collision_engine  # noqa: F401,I100 -- before tests/ joins sys.path (a namesake folder)
from collision_engine import (ConvexMesh, DistanceRequest, load_scene, read_scene, Scene,
                              STATUS_NOT_CONVERGED)
from collision_engine.mesh_io import load_mesh
from collision_engine.scene import SceneObject
from haptic_bringup.contacts import contact_intervals, MIN_FORCE
from haptic_bringup.session import published_counts, PUBLISHERS, read_session, topic_counts

ROOT = Path(__file__).resolve().parents[1]
sys.path.append(str(ROOT / 'tests'))
import bench_collision  # noqa: E402,I100,I202 -- a bench script beside this one
import extreme_cases  # noqa: E402
import ground_truth  # noqa: E402 -- needs tests/ on the path
from paper_method import PaperMethod, stl_vertex_rows  # noqa: E402
import stiff_wall_loop  # noqa: E402
import stiffness_sweep  # noqa: E402

__all__ = ['EXPERIMENTS', 'FALSE_ERROR', 'FELT_FORCE', 'PAPER', 'angles_to_normal',
           'error_summary', 'false_events', 'false_samples', 'markdown_table', 'runs', 'main']

FALSE_ERROR = 1e-3  # [m] an answer farther than this from the truth is a false value
FELT_FORCE = 0.01  # [N] weaker forces (the damper's residue as a contact ends) are not judged
SIGN_FLOOR = 1e-9  # [m] nearer the surface than this, the sign is not judged
CONTACT_SAMPLES = 3  # shorter runs inside are grazes, as for contacts.contact_intervals
ERROR_FLOOR = 1e-18  # [m] log axes draw smaller errors (exact to rounding) here
STAGES = ('bags', 'truth', 'paper', 'figures', 'timing', 'tradeoff', 'loop', 'sweep',
          'stiffwall', 'extreme', 'write')
SKIPPABLE = ('timing', 'tradeoff', 'loop', 'sweep', 'stiffwall', 'extreme')
STIFF_WALLS = (160.0, 5000.0, 20000.0)  # [N/m] over the real loop
NO_FORCE_RUN = 'cuboid-no-force'  # the demo's control run, the cuboid taps without force
LOOP_RATES = (500.0, 1000.0, 2000.0)  # [Hz]
LOOP_LAYOUTS = ('separate', 'composed')
TOLERANCES = (1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
ITERATION_CAPS = (1, 2, 3, 4, 6, 8, 12, 16, 100)
VERSIONED = ('numpy', 'scipy', 'numba', 'rclpy', 'python-fcl', 'coal', 'trimesh', 'rosbags',
             'matplotlib')


@dataclass(frozen=True)
class PaperReported:
    """What the paper reports for one experiment: reference data, typed in from the paper.

    Lengths m, forces N; ``intervals`` are (start s, end s, Fx, Fy, Fz) rows of its table.
    """

    figure: int
    vertices: int
    mean_error: float
    error_source: str
    false_values: int
    collisions: int
    mean_force: tuple
    intervals: tuple = ()
    table: str = ''


PAPER = {
    'hand': PaperReported(
        figure=1, vertices=3660, mean_error=2.1e-2, error_source='abstract', false_values=0,
        collisions=11, mean_force=(0.998, 0.996, 0.345), table='Table 1', intervals=(
            (0.2, 0.45, 2.434, 1.542, 0.8417), (1.0, 1.3, 1.799, 1.407, 0.1984),
            (1.8, 2.1, 2.204, 1.647, 0.5779), (2.65, 3.05, 1.191, 2.791, -1.133),
            (3.88, 4.25, -0.2231, 0.2434, 0.2146), (4.6, 4.95, 0.003, 0.1909, 0.7829),
            (5.5, 5.9, 0.3367, 0.2689, 0.2665), (6.3, 6.65, 0.4804, 0.3912, 0.2679),
            (6.9, 7.3, 0.7628, 0.6750, 0.4729), (7.65, 8.1, 0.8455, 0.8792, 0.5574),
            (8.35, 8.7, 1.154, 0.9189, 0.7470))),
    'cylinder': PaperReported(
        figure=2, vertices=456, mean_error=3.44e-2, error_source='Table 2', false_values=6,
        collisions=9, mean_force=(0.3561, 1.711, 0.6248)),
    'cuboid': PaperReported(
        figure=3, vertices=36, mean_error=4.176e-2, error_source='Table 2', false_values=1,
        collisions=18, mean_force=(1.62, 0.477, 0.217), table='Table 4', intervals=(
            (0.50, 1.10, -2.1, 0.3, 0.3), (1.80, 2.40, -2.9, 1.1, 0.9),
            (3.10, 3.70, -1.8, 0.9, -0.3), (4.25, 4.75, -1.9, 0.5, 0.5),
            (5.40, 5.75, -0.5, 0.1, 0.2), (6.45, 6.80, -1.1, 0.2, 0.1),
            (7.40, 7.80, -0.8, 0.3, 0.2), (8.40, 8.75, -0.3, 0.1, 0.05),
            (9.25, 9.60, -1.4, 0.3, 0.43))),
}
PAPER_TABLE_3 = {'time': 8.436, 'velocity': (0.2055, 0.0087, 0.0069),
                 'distance_vector': (-9.685e-4, 1.967e-4, 1.268e-4),
                 'force': (0.3194, 0.0245, 0.0148)}


@dataclass(frozen=True)
class Experiment:
    """One of the paper's experiments: the scene the demo ran, and the paper's STL placed so."""

    name: str
    scene: str
    paper_scene: str
    description: str


EXPERIMENTS = {
    'hand': Experiment('hand', 'hand', 'hand', 'dorsum of a hand (non-convex mesh)'),
    'cylinder': Experiment('cylinder', 'cylinder', 'paper_cylinder_stl',
                           'curved side of a cylinder r 0.025 m, h 0.1 m'),
    'cuboid': Experiment('cuboid', 'cuboid', 'paper_cuboid_stl',
                         'end face of a 0.2 x 0.1 x 0.1 m cuboid'),
}


# -- pure measures (tested in tests/bench/test_report.py) --------------------------------------

def runs(mask, min_samples: int = 1) -> list[tuple[int, int]]:
    """Index ranges [start, stop) of the runs of True in ``mask`` at least ``min_samples`` long."""
    flags = np.concatenate(([0], np.asarray(mask, dtype=np.int8), [0]))
    edges = np.flatnonzero(np.diff(flags))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2]) if b - a >= min_samples]


def false_samples(answer, truth, *, threshold: float = FALSE_ERROR,
                  sign_floor: float = SIGN_FLOOR) -> np.ndarray:
    """(n,) bool: no answer (NaN), ``|answer - truth| > threshold``, or the wrong sign.

    The sign is judged only where the truth is farther than ``sign_floor`` from the surface.
    """
    answer, truth = np.asarray(answer, dtype=float), np.asarray(truth, dtype=float)
    with np.errstate(invalid='ignore'):
        wrong_sign = (np.abs(truth) > sign_floor) & (np.sign(answer) != np.sign(truth))
        return ~np.isfinite(answer) | (np.abs(answer - truth) > threshold) | wrong_sign


def false_events(answer, truth, **options) -> tuple[int, int]:
    """Count false values as events (runs of consecutive false samples), and as samples."""
    false = false_samples(answer, truth, **options)
    return len(runs(false)), int(np.count_nonzero(false))


def error_summary(answer, truth) -> dict:
    """Mean and largest ``|answer - truth|`` over the answered samples, m; and the unanswered."""
    error = np.abs(np.asarray(answer, dtype=float) - np.asarray(truth, dtype=float))
    answered = np.isfinite(error)
    if not answered.any():
        return {'mean': math.nan, 'max': math.nan, 'unanswered': int(error.size)}
    return {'mean': float(error[answered].mean()), 'max': float(error[answered].max()),
            'unanswered': int(np.count_nonzero(~answered))}


def angles_to_normal(force, normal, *, min_force: float = MIN_FORCE) -> np.ndarray:
    """(n,) degrees between each force and unit normal; NaN where the force is below min_force."""
    force, normal = np.asarray(force, dtype=float), np.asarray(normal, dtype=float)
    magnitude = np.linalg.norm(force, axis=-1)
    with np.errstate(invalid='ignore', divide='ignore'):
        cosine = np.einsum('...i,...i->...', force, normal) / magnitude
    angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    return np.where(magnitude > min_force, angle, np.nan)


def markdown_table(header: list, rows: list) -> str:
    """Format a GitHub Markdown table; cells are printed with ``str``."""
    lines = ['| ' + ' | '.join(map(str, header)) + ' |',
             '|' + '|'.join('---' for _ in header) + '|']
    lines += ['| ' + ' | '.join(map(str, row)) + ' |' for row in rows]
    return '\n'.join(lines)


def _g(value: float, digits: int = 3) -> str:
    """Format a number in ``digits`` significant figures; '-' for NaN or None."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return '-'
    return f'{value:.{digits}g}'


def _length(value: float) -> str:
    """Format a length in metres: in mm from a micrometre up, else in m, 3 significant figures."""
    if value is None or math.isnan(value):
        return '-'
    return f'{value * 1e3:.3g} mm' if abs(value) >= 1e-6 else f'{value:.3g} m'


# -- stage 1: the bags --------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Recording:
    """What one experiment's bag and loop statistics hold (see ``haptic_bringup.session``).

    ``velocity`` (n, 3) m/s is the wand's twist stamped as each answered pose (NaN if none).
    """

    experiment: Experiment
    session: object
    velocity: np.ndarray
    contacts: list
    loop: dict
    counts: dict
    recorded_at: str
    scene_matches: bool


def _typestore():
    from haptic_bringup.bag import typestore_with
    from haptic_bringup.launcher import add_venv_prefix
    from haptic_bringup.recorder import custom_definitions

    add_venv_prefix()
    return typestore_with(custom_definitions())


def _velocities(bag: Path, typestore) -> np.ndarray:
    """(n, 3) m/s: the twist stamped as each collision state's pose, in ``read_session`` order."""
    from rosbags.highlevel import AnyReader

    twists, states = {}, set()
    with AnyReader([bag], default_typestore=typestore) as reader:
        wanted = [c for c in reader.connections
                  if c.topic in ('/wand/twist', '/collision/state')]
        for connection, _, raw in reader.messages(connections=wanted):
            message = reader.deserialize(raw, connection.msgtype)
            stamp = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec
            if connection.topic == '/wand/twist':
                linear = message.twist.linear
                twists[stamp] = (linear.x, linear.y, linear.z)
            else:
                states.add(stamp)
    missing = (math.nan,) * 3
    return np.array([twists.get(stamp, missing) for stamp in sorted(states)])


def read_recording(experiment: Experiment, demo_dir: Path, typestore) -> Recording:
    """Read one experiment's bag and loop statistics."""
    run = demo_dir / experiment.name
    bag = run / 'bag'
    if not bag.is_dir():
        raise FileNotFoundError(f'{bag}: no bag; run `demo --experiments {experiment.name}`')
    session = read_session(bag, typestore)
    recorded = topic_counts(bag)
    published = published_counts(bag, typestore)
    counts = {topic: (published.get(topic), recorded.get(topic, 0))
              for topic in sorted(published.keys() | (recorded.keys() & PUBLISHERS.keys()))}
    stats = run / 'loop_stats.npz'
    loop = {key: value for key, value in np.load(stats).items()} if stats.exists() else {}
    stamp = max(path.stat().st_mtime for path in bag.iterdir())
    scene_text = ground_truth.scene_path(experiment.scene).read_text()
    contacts = contact_intervals(session, min_samples=CONTACT_SAMPLES)
    return Recording(experiment, session, _velocities(bag, typestore), contacts, loop, counts,
                     _utc(stamp), session.scene == scene_text)


# -- stage 2: exact ground truth ----------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Truth:
    """The exact signed distance (n,) m and unit outward normal (n, 3) at each recorded tip."""

    distance: np.ndarray
    normal: np.ndarray


def exact_truth(experiment: Experiment, points: np.ndarray) -> Truth:
    """Exact signed distance and outward normal at world points (n, 3), m.

    Analytic for the box and the cylinder, with the normal as the central-difference gradient
    of the exact field; brute force for the mesh, with the normal along tip - closest point.
    """
    spec = read_scene(ground_truth.scene_path(experiment.scene)).objects[0]
    rotation, translation = spec.pose.rotation, spec.pose.translation

    def local(world):
        return (np.asarray(world) - translation) @ rotation

    shape = spec.shape
    if hasattr(shape, 'file'):
        mesh = load_mesh(shape.file, scale=shape.scale, check_self_intersection=False)
        signed, closest = ground_truth.mesh_signed_distance(local(points), mesh.vertices,
                                                            mesh.faces)
        with np.errstate(invalid='ignore', divide='ignore'):
            normal = (local(points) - closest) / signed[:, None]
        return Truth(signed, normal @ rotation.T)
    if hasattr(shape, 'size'):
        def field(world):
            return ground_truth.box_signed_distance(local(world), shape.size)
    else:
        def field(world):
            return ground_truth.cylinder_signed_distance(local(world), shape.radius,
                                                         shape.height)
    return Truth(field(points), bench_collision._outward(field, points))


# -- stage 3: the paper's method along the same trajectory --------------------------------------

@dataclass(frozen=True, eq=False)
class PaperReplay:
    """The paper's code on our trajectory, sample by sample.

    flag (n,) bool, unsigned and signed distance (n,) m, outcome per sample (n,) str, force
    (n, 3) N, and the STL rows (m, 3) m it used.
    """

    flag: np.ndarray
    distance: np.ndarray
    signed: np.ndarray
    outcome: np.ndarray
    force: np.ndarray
    rows: np.ndarray


def paper_rows(experiment: Experiment) -> tuple[np.ndarray, object]:
    """Read the paper's STL vertex rows for an experiment, placed as our object (world, m)."""
    spec = read_scene(ground_truth.scene_path(experiment.paper_scene)).objects[0]
    rows = stl_vertex_rows(spec.shape.file, scale=spec.shape.scale)
    return rows @ spec.pose.rotation.T + spec.pose.translation, spec.material


def replay_paper(experiment: Experiment, tips: np.ndarray, velocity: np.ndarray) -> PaperReplay:
    """Run the paper's flag, distance and force on every recorded tip position."""
    rows, material = paper_rows(experiment)
    method = PaperMethod(rows, stiffness=float(material.stiffness[0]), damping=material.damping)
    answers = [method.query(tip) for tip in tips]
    force = np.array([method.force_for(a, tip, v) for a, tip, v in zip(answers, tips, velocity)])
    return PaperReplay(np.array([a.in_collision for a in answers]),
                       np.array([a.distance.distance for a in answers]),
                       np.array([a.signed_distance for a in answers]),
                       np.array([a.distance.outcome for a in answers]), force, rows)


# -- per-experiment measures --------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class Measures:
    """Everything the report says about one experiment, computed from its arrays."""

    ours: dict
    paper: dict
    ours_events: tuple
    paper_events: tuple
    ours_angles: np.ndarray
    paper_angles: np.ndarray
    ours_all_angles: np.ndarray
    paper_all_angles: np.ndarray
    paper_missed: int
    paper_false_flags: int
    truth_contacts: int
    paper_contacts: int
    outcomes: dict


def measure(recording: Recording, truth: Truth, replay: PaperReplay) -> Measures:
    """Errors, false values, contacts and force directions of ours and of the paper's code."""
    session = recording.session
    inside = truth.distance < 0.0

    def in_contact(force, min_force):
        return np.where(inside, angles_to_normal(force, truth.normal, min_force=min_force),
                        np.nan)

    outcomes = {k: int(np.count_nonzero(replay.outcome == k))
                for k in ('converged', 'cap', 'hang')}
    return Measures(
        ours=error_summary(session.distance, truth.distance),
        paper=error_summary(replay.signed, truth.distance),
        ours_events=false_events(session.distance, truth.distance),
        paper_events=false_events(replay.signed, truth.distance),
        ours_angles=in_contact(session.force, FELT_FORCE),
        paper_angles=in_contact(replay.force, FELT_FORCE),
        ours_all_angles=in_contact(session.force, MIN_FORCE),
        paper_all_angles=in_contact(replay.force, MIN_FORCE),
        paper_missed=int(np.count_nonzero(inside & ~replay.flag)),
        paper_false_flags=int(np.count_nonzero(~inside & replay.flag)),
        truth_contacts=len(runs(inside, CONTACT_SAMPLES)),
        paper_contacts=len(runs(replay.flag, CONTACT_SAMPLES)),
        outcomes=outcomes)


def _angle_stats(angles: np.ndarray) -> tuple[float, float]:
    kept = angles[np.isfinite(angles)]
    return (float(kept.mean()), float(kept.max())) if kept.size else (math.nan, math.nan)


def _worst(angles: np.ndarray, time: np.ndarray, force: np.ndarray) -> str:
    """Say when the largest angle happened and how strong that force was."""
    if not np.isfinite(angles).any():
        return 'no force in contact'
    k = int(np.nanargmax(angles))
    return f'at t = {time[k]:.3f} s, |F| = {1e3 * np.linalg.norm(force[k]):.3g} mN'


# -- stage 4: figures ---------------------------------------------------------------------------

def _pyplot():
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    return plt


def _floor(values) -> np.ndarray:
    return np.maximum(np.abs(np.asarray(values, dtype=float)), ERROR_FLOOR)


def experiment_figure(recording: Recording, truth: Truth, replay: PaperReplay,
                      measures: Measures, path: Path) -> None:
    """Draw the paper's Figure 1/2/3 for one experiment: (a) vertices, (b) distance, (c) force."""
    plt = _pyplot()
    from matplotlib.gridspec import GridSpec

    session = recording.session
    name = recording.experiment.name
    figure = plt.figure(figsize=(16, 13), constrained_layout=True)
    grid = GridSpec(3, 3, figure=figure, height_ratios=(1.3, 1.0, 0.8))
    _vertices_panel(figure.add_subplot(grid[0, 0], projection='3d'), replay.rows, session.tip,
                    name)
    distance_axes = figure.add_subplot(grid[0, 1:])
    _distance_panel(distance_axes, session, truth, replay)
    _force_panel(figure.add_subplot(grid[1, :], sharex=distance_axes), session, replay)
    _angle_panel(figure.add_subplot(grid[2, :], sharex=distance_axes), session.time, measures)
    figure.suptitle(f'{name}: the paper\'s Figure {PAPER[name].figure}, reproduced')
    figure.savefig(path, dpi=90)
    plt.close(figure)


def _vertices_panel(axes, rows: np.ndarray, tips: np.ndarray, name: str) -> None:
    unique = np.unique(rows, axis=0)
    shown = unique[::max(1, len(unique) // 4000)]
    axes.scatter(*(1e3 * shown.T), s=2, c='0.35', depthshade=False,
                 label=f'{len(rows)} STL vertex rows ({len(unique)} distinct)')
    axes.plot(*(1e3 * tips.T), lw=0.8, c='C3', label='tip path (recorded)')
    extent = np.ptp(np.vstack((shown, tips)), axis=0)
    axes.set_box_aspect(np.maximum(extent, 1e-3 * extent.max()))
    axes.set_xlabel('x mm')
    axes.set_ylabel('y mm')
    axes.set_zlabel('z mm')
    axes.set_title(f'(a) {name}: the paper\'s STL vertices, the tip\'s path')
    axes.legend(loc='upper left', fontsize=7)


def _distance_panel(axes, session, truth: Truth, replay: PaperReplay) -> None:
    t = session.time
    axes.plot(t, 1e3 * truth.distance, c='k', lw=1.2, label='exact (ground truth)')
    axes.plot(t, 1e3 * session.distance, c='C0', lw=1.0, ls='--', label='ours (recorded)')
    axes.plot(t, 1e3 * replay.signed, c='C1', lw=0.8, label='paper\'s method (replayed)')
    axes.set_ylabel('signed distance mm')
    axes.set_title('(b) distance against time, and |error| (right, log)')
    errors = axes.twinx()
    errors.semilogy(t, _floor(session.distance - truth.distance), '.', c='C0', ms=1.5)
    errors.semilogy(t, _floor(replay.signed - truth.distance), '.', c='C1', ms=1.5)
    errors.axhline(FALSE_ERROR, c='C3', lw=0.8, ls=':')
    errors.set_ylabel(f'|error| m, dots (< {ERROR_FLOOR:g} drawn at it; red: 1 mm)')
    axes.legend(loc='upper center', bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=8)


def _force_panel(axes, session, replay: PaperReplay) -> None:
    for axis, label in enumerate('xyz'):
        axes.plot(session.time, session.force[:, axis], c=f'C{axis}', lw=1.0,
                  label=f'F{label} ours')
        axes.plot(session.time, replay.force[:, axis], c=f'C{axis}', lw=0.8, ls='--',
                  label=f'F{label} paper\'s law')
    axes.set_ylabel('force N')
    axes.set_title('(c) force against time: ours (solid), the paper\'s law replayed (dashed)')
    axes.legend(loc='upper right', fontsize=7, ncol=3)


def _angle_panel(axes, t: np.ndarray, measures: Measures) -> None:
    for all_angles, felt, colour, label in (
            (measures.ours_all_angles, measures.ours_angles, 'C0', 'ours'),
            (measures.paper_all_angles, measures.paper_angles, 'C1', 'paper\'s law')):
        axes.plot(t, all_angles, '.', c=colour, ms=1.5, alpha=0.35)
        axes.plot(t, felt, '.', c=colour, ms=2.5, label=f'{label}, |F| >= {FELT_FORCE:g} N')
    axes.set_ylabel('angle to exact normal, deg')
    axes.set_xlabel('time s')
    axes.set_title('(c) force direction error in contact: the angle between F and the exact '
                   f'outward normal (faint: forces under {FELT_FORCE:g} N)')
    axes.legend(loc='upper right', fontsize=8)


def headline_figure(results: dict, path: Path) -> None:
    """Distance error and force direction error per experiment, ours beside the paper's."""
    plt = _pyplot()
    names = list(results)
    x = np.arange(len(names))
    figure, (left, right) = plt.subplots(1, 2, figsize=(13, 5.5), constrained_layout=True)
    bars = [('ours, mean', [results[n].ours['mean'] for n in names], 'C0', None),
            ('ours, max', [results[n].ours['max'] for n in names], 'C0', '//'),
            ('paper\'s method on our trajectory, mean', [results[n].paper['mean']
                                                         for n in names], 'C1', None),
            ('paper\'s method on our trajectory, max', [results[n].paper['max']
                                                        for n in names], 'C1', '//'),
            ('paper, reported mean', [PAPER[n].mean_error for n in names], 'C3', None)]
    for k, (label, values, colour, hatch) in enumerate(bars):
        drawn = left.bar(x + (k - 2) * 0.16, _floor(values), 0.16, color=colour, hatch=hatch,
                         edgecolor='k', lw=0.4, label=label)
        left.bar_label(drawn, labels=[_length(v) for v in values], fontsize=6, rotation=90,
                       padding=2)
    left.set_yscale('log')
    left.set_xticks(x, names)
    left.set_ylabel(f'|distance error| m (< {ERROR_FLOOR:g} drawn at it)')
    left.set_ylim(ERROR_FLOOR / 10, 10.0)
    left.set_title('distance error')
    left.legend(fontsize=7, loc='upper left', bbox_to_anchor=(0.0, -0.08), ncol=2)
    for k, (label, colour) in enumerate((('ours', 'C0'), ('paper\'s law', 'C1'))):
        stats = [_angle_stats(results[n].ours_angles if k == 0 else results[n].paper_angles)
                 for n in names]
        for j, (which, hatch) in enumerate((('mean', None), ('max', '//'))):
            drawn = right.bar(x + (2 * k + j - 1.5) * 0.2, [s[j] for s in stats], 0.2,
                              color=colour, hatch=hatch, edgecolor='k', lw=0.4,
                              label=f'{label}, {which}')
            right.bar_label(drawn, fmt='%.3g°', fontsize=7, padding=2)
    right.set_xticks(x, names)
    right.set_ylabel('degrees')
    right.set_title(f'force direction error in contact (|F| >= {FELT_FORCE:g} N)')
    right.legend(fontsize=7, loc='upper left', bbox_to_anchor=(0.0, -0.08), ncol=2)
    figure.savefig(path, dpi=90)
    plt.close(figure)


# -- stage 5: error against run time ------------------------------------------------------------

def _paper_function(rows: np.ndarray):
    method = PaperMethod(rows)
    return (lambda point: method.query(point).signed_distance), list


def _trimesh_function(experiment: Experiment):
    import trimesh
    import trimesh.proximity

    rows, _ = paper_rows(experiment)
    mesh = trimesh.Trimesh(rows, np.arange(len(rows)).reshape(-1, 3))
    mesh.merge_vertices()
    trimesh.proximity.signed_distance(mesh, rows[:1])  # raises now if rtree is missing

    def signed_distance(point):
        return -float(trimesh.proximity.signed_distance(mesh, point[None])[0])

    return signed_distance, list


def _hull_object(experiment: Experiment, exact: SceneObject) -> SceneObject:
    """Our GJK on the convex hull of the paper's STL, placed as the exact object."""
    if experiment.paper_scene != experiment.scene:
        return load_scene(ground_truth.scene_path(experiment.paper_scene)).objects[0]
    return SceneObject(f'{exact.name} hull', ConvexMesh(exact.shape.vertices), exact.pose)


def _methods(experiment: Experiment, exact: SceneObject) -> list:
    """List (method, geometry, factory) for every method on one object."""
    exact_kind = type(exact.shape).__name__
    ours_exact = ('ours: exact mesh (BVH + pseudonormals)' if exact_kind == 'TriangleMesh'
                  else 'ours: GJK, exact primitive')
    methods = bench_collision.METHODS
    return [
        (ours_exact, exact_kind, lambda: methods['ours'](exact)),
        ('ours: GJK on the STL\'s convex hull', 'ConvexMesh',
         lambda: methods['ours'](_hull_object(experiment, exact))),
        ('paper\'s method (re-implemented)', 'STL vertex rows',
         lambda: _paper_function(paper_rows(experiment)[0])),
        ('python-fcl', exact_kind, lambda: methods['python-fcl'](exact)),
        ('coal', exact_kind, lambda: methods['coal'](exact)),
        ('trimesh signed_distance', 'STL mesh', lambda: _trimesh_function(experiment)),
    ]


def error_time_rows(*, random: int, near: int, tapping: float, slow_points: int,
                    seed: int = 0) -> list[dict]:
    """Per object and method: per-query time and error against exact truth.

    Every method answers the same points (``bench_collision.point_sets``: random in twice the
    bounding box, within +-2 mm of the surface, a 1 kHz tapping path), one Python call each,
    timed as ``bench_collision`` times its methods; trimesh answers every k-th point only, for
    ``slow_points`` in all. A method that cannot run says why.
    """
    rows = []
    for experiment in EXPERIMENTS.values():
        exact = load_scene(ground_truth.scene_path(experiment.scene)).objects[0]
        sets = bench_collision.point_sets(exact, random=random, near=near, tapping=tapping,
                                          seed=seed)
        points = np.vstack([p for p, _ in sets.values()])
        truth = np.concatenate([d for _, d in sets.values()])
        for method, geometry, factory in _methods(experiment, exact):
            row = {'object': experiment.name, 'method': method, 'geometry': geometry}
            try:
                function, convert = factory()
            except ImportError as error:
                rows.append({**row, 'unavailable': f'{type(error).__name__}: {error}'})
                continue
            pick = slice(None, None, max(1, len(points) // slow_points)) if method.startswith(
                'trimesh') else slice(None)
            durations, answers = bench_collision._time_calls(function, convert(points[pick]))
            rows.append({**row, 'n': len(answers), 'median_us': float(np.median(durations)),
                         'p99_us': float(np.percentile(durations, 99)),
                         **error_summary(answers, truth[pick]),
                         'sign_errors': int(np.count_nonzero(
                             false_samples(answers, truth[pick], threshold=math.inf)))})
    return rows


def error_time_figure(rows: list[dict], path: Path) -> None:
    """Log-log scatter: mean (filled) and max (open) |error| against median time per query."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(11, 6.5), constrained_layout=True)
    methods = sorted({r['method'] for r in rows if 'median_us' in r})
    markers = dict(zip(methods, 'osD^vP*X'))
    colours = {name: f'C{k}' for k, name in enumerate(EXPERIMENTS)}
    for r in rows:
        if 'median_us' not in r:
            continue
        x, mean, top = r['median_us'], max(r['mean'], ERROR_FLOOR), max(r['max'], ERROR_FLOOR)
        colour, marker = colours[r['object']], markers[r['method']]
        axes.plot([x, x], [mean, top], c=colour, lw=0.6)
        axes.plot(x, mean, marker, c=colour, ms=8)
        axes.plot(x, top, marker, mfc='none', c=colour, ms=8)
    for name, colour in colours.items():
        axes.plot([], [], 's', c=colour, label=name)
    for method, marker in markers.items():
        axes.plot([], [], marker, c='0.4', label=method)
    axes.set_xscale('log')
    axes.set_yscale('log')
    axes.set_xlabel('median time per query, us (one Python call)')
    axes.set_ylabel(f'|distance error| m: mean filled, max open (< {ERROR_FLOOR:g} drawn at it)')
    axes.set_title('error against run time, per object and method')
    axes.legend(fontsize=8, loc='center left', bbox_to_anchor=(1.0, 0.5))
    figure.savefig(path, dpi=90)
    plt.close(figure)


# -- stage 6: our GJK's tolerance and iteration-cap trade-off ------------------------------------

def tradeoff_rows(points: int, seed: int = 0) -> list[dict]:
    """Error and time of our GJK as its tolerance and iteration cap vary.

    On the true cylinder (analytic support) and the hand's convex hull (hundreds of vertices),
    one ``Scene.query`` per point as the collision node makes them, in a scene built with the
    ``DistanceRequest`` of each setting, over the same points per shape (random, near the
    surface, tapping); truth as elsewhere.
    """
    cylinder = load_scene(ground_truth.scene_path('cylinder')).objects[0]
    hand = load_scene(ground_truth.scene_path('hand')).objects[0]
    shapes = {'cylinder (exact)': cylinder,
              'hand\'s convex hull': _hull_object(EXPERIMENTS['hand'], hand)}
    settings = ([('tolerance', t, DistanceRequest(rel_tol=t, abs_tol=t)) for t in TOLERANCES]
                + [('iteration cap', k, DistanceRequest(max_iterations=k))
                   for k in ITERATION_CAPS])
    rows = []
    for label, scene_object in shapes.items():
        sets = bench_collision.point_sets(scene_object, random=points // 2, near=points // 2,
                                          tapping=0.1, seed=seed)
        world = np.vstack([p for p, _ in sets.values()])
        inputs = [tuple(point) for point in world]
        truth = np.concatenate([d for _, d in sets.values()])
        for sweep, value, request in settings:
            scene = Scene([scene_object], request=request)
            scene.warm_up()
            durations, answers = bench_collision._time_calls(
                lambda p, query=scene.query: query(p).distance, inputs)
            results = [scene.query(p) for p in inputs]
            rows.append({'shape': label, 'sweep': sweep, 'value': value,
                         'median_us': float(np.median(durations)),
                         'p99_us': float(np.percentile(durations, 99)),
                         **error_summary(answers, truth),
                         'iterations': float(np.mean([r.iterations for r in results])),
                         'not_converged': int(sum(r.status == STATUS_NOT_CONVERGED
                                                  for r in results)),
                         'n': len(inputs)})
    return rows


def tradeoff_figure(rows: list[dict], path: Path) -> None:
    """Mean and max |error| against median time as the tolerance and the cap vary."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(10, 6), constrained_layout=True)
    for k, shape in enumerate(sorted({r['shape'] for r in rows})):
        for sweep, style in (('tolerance', '-o'), ('iteration cap', '--s')):
            chosen = [r for r in rows if r['shape'] == shape and r['sweep'] == sweep]
            x = [r['median_us'] for r in chosen]
            axes.plot(x, _floor([r['mean'] for r in chosen]), style, c=f'C{k}',
                      label=f'{shape}, {sweep}: mean')
            axes.plot(x, _floor([r['max'] for r in chosen]), style, c=f'C{k}', mfc='none',
                      alpha=0.6, label=f'{shape}, {sweep}: max')
            for r, xi in zip(chosen, x):
                axes.annotate(f'{r["value"]:g}', (xi, max(r['max'], ERROR_FLOOR)), fontsize=6,
                              textcoords='offset points', xytext=(3, 3))
    axes.set_xscale('log')
    axes.set_yscale('log')
    axes.set_xlabel('median time per query, us')
    axes.set_ylabel(f'|distance error| m (< {ERROR_FLOOR:g} drawn at it)')
    axes.set_title('our GJK: accuracy against time as rel_tol = abs_tol (m) and the '
                   'iteration cap vary (labels)')
    axes.legend(fontsize=7)
    figure.savefig(path, dpi=90)
    plt.close(figure)


# -- stage 7: loop latency ----------------------------------------------------------------------

def loop_rows(duration: float, domain_id: int) -> list[dict]:
    """One ``bench_loop.run_once`` per layout and pose rate (0.5, 1 and 2 kHz)."""
    import bench_loop

    rows = []
    for layout in LOOP_LAYOUTS:
        for rate in LOOP_RATES:
            row = {'layout': layout, 'rate': rate, 'duration': duration}
            try:
                record = bench_loop.run_once(layout, rate, duration, domain_id)
            except RuntimeError as error:
                rows.append({**row, 'failed': str(error)})
                continue
            latency = np.asarray(record['latencies'], dtype=float)
            rows.append({**row, 'achieved': float(record['rate_hz']),
                         'answered': float(record['answered_percent']),
                         'cpu': float(record['cpu_percent']), 'n': int(latency.size),
                         **{f'p{q}': float(np.percentile(latency, q)) for q in (50, 90, 99)},
                         'max': float(latency.max())})
    return rows


def loop_figure(rows: list[dict], path: Path) -> None:
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    for k, layout in enumerate(LOOP_LAYOUTS):
        chosen = [r for r in rows if r['layout'] == layout and 'p50' in r]
        rates = [r['rate'] for r in chosen]
        for key, style in (('p50', '-o'), ('p99', '--s'), ('max', ':^')):
            axes.plot(rates, [1e3 * r[key] for r in chosen], style, c=f'C{k}',
                      label=f'{layout}, {key}')
    axes.set_xscale('log')
    axes.set_yscale('log')
    axes.set_xticks(LOOP_RATES, [f'{r:g}' for r in LOOP_RATES])
    axes.minorticks_off()
    axes.axhline(1.0, c='0.5', lw=0.6)
    axes.set_xlabel('pose rate set, Hz')
    axes.set_ylabel('round trip pose -> wrench, ms')
    axes.set_title('end-to-end loop latency over ROS 2')
    axes.legend(fontsize=8)
    figure.savefig(path, dpi=90)
    plt.close(figure)


# -- stage 8: stiffness sweep -------------------------------------------------------------------

def sweep_figure(rows: list, bound: float, path: Path) -> None:
    """Energy generated and oscillation decay against K, per passivity mode."""
    plt = _pyplot()
    figure, (energy, decay) = plt.subplots(1, 2, figsize=(13, 4.5), constrained_layout=True)
    for k, mode in enumerate(stiffness_sweep.MODES):
        chosen = [r for r in rows if r.mode == mode]
        stiffness = [r.stiffness for r in chosen]
        energy.plot(stiffness, [r.generated_energy for r in chosen], '-o', c=f'C{k}',
                    label=f'passivity {mode}')
        decay.plot(stiffness, [r.decay_ratio for r in chosen], '-o', c=f'C{k}',
                   label=f'passivity {mode}')
    for axes in (energy, decay):
        axes.set_xscale('log')
        axes.axvline(bound, c='C3', lw=0.8, ls=':', label=f'Colgate bound {bound:.0f} N/m')
        axes.set_xlabel('wall stiffness K, N/m')
        axes.legend(fontsize=8)
    energy.set_yscale('symlog', linthresh=1e-4)
    energy.set_ylabel('energy generated by the rendering, J (> 0: active)')
    energy.set_title('energy against K')
    decay.set_yscale('log')
    decay.set_ylabel('late / early oscillation amplitude in the hold')
    decay.set_title('oscillation decay against K (< 1 decays)')
    figure.savefig(path, dpi=90)
    plt.close(figure)


# -- provenance ---------------------------------------------------------------------------------

def _utc(stamp: float) -> str:
    return datetime.datetime.fromtimestamp(stamp, datetime.timezone.utc).strftime(
        '%Y-%m-%d %H:%M UTC')


def _git(*args: str) -> str:
    try:
        done = subprocess.run(['git', *args], cwd=ROOT, capture_output=True, text=True,
                              timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return ''
    return done.stdout.strip() if done.returncode == 0 else ''


def provenance() -> dict:
    """Describe the machine, the versions, the date and the commit the report is made on."""
    machine = bench_machine.describe()
    versions = {}
    for package in VERSIONED:
        try:
            versions[package] = version(package)
        except PackageNotFoundError:
            versions[package] = 'not installed'
    commit = _git('rev-parse', 'HEAD') or 'unknown'
    dirty = _git('status', '--porcelain', '--untracked-files=no')
    return {'date': _utc(time.time()), 'cpu': machine['cpu'], 'cores': machine['cores'],
            'python': platform.python_version(), 'platform': platform.platform(),
            'commit': commit + (' (with uncommitted changes)' if dirty else ''),
            'versions': versions}


# -- the Markdown -------------------------------------------------------------------------------

def _provenance_section(info: dict, recordings: dict, argv: list) -> str:
    versions = ', '.join(f'{k} {v}' for k, v in info['versions'].items())
    bags = ', '.join(f'{n} {r.recorded_at}' for n, r in recordings.items())
    return '\n'.join([
        f'- **Made** {info["date"]} by `python bench/report.py {" ".join(argv)}`, commit '
        f'`{info["commit"]}`',
        f'- **Machine** {info["cpu"]}, {info["cores"]} cores, {info["platform"]}; Python '
        f'{info["python"]}',
        f'- **Versions** {versions}',
        f'- **Bags** (demo over ROS 2, recorded) {bags}',
    ])


def _headline_section(recordings: dict, results: dict) -> str:
    header = ['experiment', 'samples', 'mean abs. error: ours', 'paper\'s method on our path',
              'paper (reported)', 'max abs. error: ours', 'paper\'s method on our path',
              'false values (events): ours', 'paper\'s method', 'paper (reported)',
              'force direction error, mean / max: ours', 'paper\'s law on the same contacts']
    rows = []
    for name, m in results.items():
        ours_angle, paper_angle = _angle_stats(m.ours_angles), _angle_stats(m.paper_angles)
        rows.append([
            name, len(recordings[name].session.time), _length(m.ours['mean']),
            _length(m.paper['mean']), _length(PAPER[name].mean_error),
            _length(m.ours['max']), _length(m.paper['max']), m.ours_events[0],
            m.paper_events[0], PAPER[name].false_values,
            f'{_g(ours_angle[0])}° / {_g(ours_angle[1])}°',
            f'{_g(paper_angle[0])}° / {_g(paper_angle[1])}°'])
    return markdown_table(header, rows)


DEFINITIONS = f"""\
How to read it:

- **Error** is the answer minus the exact signed distance at the same tip position (negative
  inside), over every answered pose of the 10 s run. *Ours* is what the collision engine
  published during the run, read from the bag. *The paper's method* is the paper's own MATLAB
  collision code, re-implemented line by line (`bench/paper_method.py`), run on the same tip
  positions against the paper's STL object placed as ours: its distance is unsigned, so it is
  signed here by its own collision flag (negative when the flag is set), the reading most
  favourable to it. *Paper (reported)* is the number printed in the paper, for its own runs;
  for the cylinder and the cuboid its text gives that average over its miscalculated instants
  only, so it compares with a *max* here more than with a mean.
- A **false value** is a sample with no answer, an error above {FALSE_ERROR * 1e3:g} mm, or the
  wrong sign (where the truth is more than {SIGN_FLOOR:g} m from the surface); consecutive false
  samples count as one event.
- **Force direction error** is the angle between the force and the exact outward normal at the
  tip, over the samples where the tip is truly inside and the force is at least
  {FELT_FORCE * 1e3:g} mN (1-2 % of a tap's peak). Weaker forces are the damper's residue in
  the last millisecond of a contact, where our unilateral clip leaves only a tangential
  millinewton (90°) and the paper's law pulls inward (180°); each experiment's section also
  gives the maximum over every force above {MIN_FORCE:g} N.
  *Ours* is the recorded wrench (our spring-damper along the normal, passivity and saturation
  on). *The paper's law* is F = (r/|r|) k dist - kd v with r = tip - centroid of the STL's
  vertex rows, its distance and flag from its code, v the recorded twist.
- The exact truth: analytic for the box and the cylinder, brute force over every triangle with
  a winding-number sign for the hand (`tests/ground_truth.py`, no code shared with the engine)."""


def _experiment_section(recording: Recording, replay: PaperReplay, m: Measures,
                        figure: str) -> str:
    name = recording.experiment.name
    paper = PAPER[name]
    ours_angle, paper_angle = _angle_stats(m.ours_angles), _angle_stats(m.paper_angles)
    loop = recording.loop
    lines = [
        f'### {name}: {recording.experiment.description} (the paper\'s Figure {paper.figure})',
        '', f'![{name}]({figure})', '',
        f'- {len(recording.session.time)} answered poses in {recording.session.time[-1]:.2f} s; '
        f'{m.truth_contacts} contacts by the exact truth, {len(recording.contacts)} by our '
        f'engine, {m.paper_contacts} by the paper\'s collision flag on the same path (the paper '
        f'reports {paper.collisions}).',
        f'- Distance error, ours: mean {_length(m.ours["mean"])}, max {_length(m.ours["max"])}; '
        f'false values {m.ours_events[0]} events ({m.ours_events[1]} samples).',
        f'- The paper\'s method on the same path: mean {_length(m.paper["mean"])}, max '
        f'{_length(m.paper["max"])}; false values {m.paper_events[0]} events '
        f'({m.paper_events[1]} samples); its flag missed {m.paper_missed} samples inside and '
        f'was set on {m.paper_false_flags} outside; its distance search converged on '
        f'{m.outcomes["converged"]}, gave up at the cap (returning its last, not its best, '
        f'triangle) on {m.outcomes["cap"]}, and would never finish in MATLAB on '
        f'{m.outcomes["hang"]} samples. The paper reports a mean error of '
        f'{_length(paper.mean_error)} ({paper.error_source}) and {paper.false_values} false '
        'values.',
        f'- Force direction error in contact (forces of {FELT_FORCE * 1e3:g} mN or more): ours '
        f'mean {_g(ours_angle[0])}°, max {_g(ours_angle[1])}° '
        f'({_worst(m.ours_angles, recording.session.time, recording.session.force)}); the '
        f'paper\'s law mean {_g(paper_angle[0])}°, max {_g(paper_angle[1])}° '
        f'({_worst(m.paper_angles, recording.session.time, replay.force)}). Over every force '
        f'above {MIN_FORCE:g} N the maxima are {_g(_angle_stats(m.ours_all_angles)[1])}° '
        f'(ours) and {_g(_angle_stats(m.paper_all_angles)[1])}° (the paper\'s law).',
    ]
    if loop:
        lines.append(
            f'- Loop during this run: {float(loop["rate_hz"]):.0f} Hz poses, '
            f'{float(loop["answered_percent"]):.1f} % answered, round trip p50 '
            f'{1e3 * float(loop["latency_p50_s"]):.2f} ms, p99 '
            f'{1e3 * float(loop["latency_p99_s"]):.2f} ms, max '
            f'{1e3 * float(loop["latency_max_s"]):.2f} ms.')
    if not recording.scene_matches:
        lines.append('- **The bag\'s scene differs from the shipped scene file**: the truth '
                     'uses the shipped one.')
    return '\n'.join(lines)


def _interval_table(recording: Recording, truth: Truth, replay: PaperReplay) -> str:
    """Per contact interval: our mean force and direction error, the paper's law, the paper's."""
    session, paper = recording.session, PAPER[recording.experiment.name]
    header = ['#', 'ours: interval s', 'Fx N', 'Fy N', 'Fz N', '∠ normal °',
              'paper\'s law, same samples: Fx', 'Fy', 'Fz', '∠ normal °']
    if paper.intervals:
        header += [f'paper ({paper.table}): interval s', 'Fx', 'Fy', 'Fz']
    rows = []
    count = max(len(recording.contacts), len(paper.intervals))
    for k in range(count):
        row = [k + 1]
        if k < len(recording.contacts):
            c = recording.contacts[k]
            window = (session.time >= c.start) & (session.time <= c.end)
            ours = angles_to_normal(session.force[window], truth.normal[window],
                                    min_force=FELT_FORCE)
            law = angles_to_normal(replay.force[window], truth.normal[window],
                                   min_force=FELT_FORCE)
            row += [f'{c.start:.2f}–{c.end:.2f}', *(_g(f) for f in c.mean_force),
                    _g(np.nanmean(ours) if np.isfinite(ours).any() else math.nan),
                    *(_g(f) for f in np.nanmean(replay.force[window], axis=0)),
                    _g(np.nanmean(law) if np.isfinite(law).any() else math.nan)]
        else:
            row += [''] * 9
        if paper.intervals:
            row += ([f'{paper.intervals[k][0]:g}–{paper.intervals[k][1]:g}',
                     *(f'{f:g}' for f in paper.intervals[k][2:])]
                    if k < len(paper.intervals) else [''] * 4)
        rows.append(row)
    inside = truth.distance < 0.0
    mean_abs = np.nanmean(np.abs(session.force[inside]), axis=0)
    law_abs = np.nanmean(np.abs(replay.force[inside]), axis=0)
    rows.append(['all', 'mean \\|F\\| in contact', *(_g(f) for f in mean_abs), '',
                 *(_g(f) for f in law_abs), ''] + (
        ['paper, as reported', *(f'{f:g}' for f in paper.mean_force)]
        if paper.intervals else []))
    table = markdown_table(header, rows)
    if not paper.intervals:
        table += (f'\n\nThe paper gives no interval table here; its mean contact forces were '
                  f'{", ".join(f"{f:g}" for f in paper.mean_force)} N (x, y, z).')
    return table


def _table_2(results: dict, replays: dict) -> str:
    header = ['object', 'vertices: paper', 'ours', 'paper\'s method (rows)',
              'mean abs. error: paper (reported)', 'paper\'s method on our path', 'ours',
              'false values: paper', 'paper\'s method', 'ours',
              'collisions: paper', 'paper\'s flag on our path', 'exact truth on our path']
    rows = []
    for name, m in results.items():
        paper = PAPER[name]
        rows.append([name, paper.vertices, _exact_geometry(EXPERIMENTS[name]),
                     len(replays[name].rows), _length(paper.mean_error),
                     _length(m.paper['mean']), _length(m.ours['mean']), paper.false_values,
                     m.paper_events[0],
                     m.ours_events[0], paper.collisions, m.paper_contacts, m.truth_contacts])
    return markdown_table(header, rows)


def _exact_geometry(experiment: Experiment) -> str:
    """Describe the object our engine queried: a primitive, or a mesh's welded vertices."""
    shape = read_scene(ground_truth.scene_path(experiment.scene)).objects[0].shape
    if not hasattr(shape, 'file'):
        return f'exact {type(shape).__name__.removesuffix("Spec").lower()} primitive'
    mesh = load_mesh(shape.file, scale=shape.scale, check_self_intersection=False)
    return f'exact mesh, {len(mesh.vertices)} vertices'


def _table_3(recording: Recording) -> str:
    """Set the paper's hand check of one instant beside the same check of our deepest push."""
    session = recording.session
    k = int(np.argmin(session.distance))
    material = read_scene(ground_truth.scene_path(recording.experiment.scene)).objects[0]
    stiffness, damping = material.material.stiffness, material.material.damping
    velocity = recording.velocity[k]
    vector = session.point[k] - session.tip[k]
    law = stiffness * vector - damping * velocity
    header = ['', 'paper: t = 8.436 s: v m/s', 'distance vector m', 'F N',
              f'ours: t = {session.time[k]:.3f} s: v m/s', 'x = point - tip m',
              'K x - C v N', 'F published N']
    rows = [[axis, _g(PAPER_TABLE_3['velocity'][i], 4), _g(PAPER_TABLE_3['distance_vector'][i], 4),
             _g(PAPER_TABLE_3['force'][i], 4), _g(velocity[i], 4), _g(vector[i], 4),
             _g(law[i], 4), _g(session.force[k, i], 4)] for i, axis in enumerate('XYZ')]
    return markdown_table(header, rows)


def _error_time_section(rows: list[dict]) -> str:
    header = ['object', 'method', 'geometry', 'n', 'median us', 'p99 us', 'mean abs. error m',
              'max abs. error m', 'sign errors']
    table = []
    for r in rows:
        if 'unavailable' in r:
            table.append([r['object'], r['method'], r['geometry'], '-', '-', '-', '-', '-',
                          f'not run: {r["unavailable"]}'])
            continue
        table.append([r['object'], r['method'], r['geometry'], r['n'], _g(r['median_us']),
                      _g(r['p99_us']), _g(r['mean']), _g(r['max']), r['sign_errors']])
    return markdown_table(header, table)


def _tradeoff_section(rows: list[dict]) -> str:
    header = ['shape', 'sweep', 'value', 'median us', 'p99 us', 'mean iterations',
              'not converged', 'mean abs. error m', 'max abs. error m']
    return markdown_table(header, [
        [r['shape'], r['sweep'], f'{r["value"]:g}', _g(r['median_us']), _g(r['p99_us']),
         _g(r['iterations']), f'{r["not_converged"]}/{r["n"]}', _g(r['mean']), _g(r['max'])]
        for r in rows])


def _loop_section(rows: list[dict]) -> str:
    header = ['layout', 'rate set Hz', 'achieved Hz', 'answered %', 'p50 ms', 'p90 ms',
              'p99 ms', 'max ms', 'CPU % of a core']
    table = []
    for r in rows:
        if 'failed' in r:
            table.append([r['layout'], f'{r["rate"]:g}', f'failed: {r["failed"]}'] + [''] * 6)
            continue
        table.append([r['layout'], f'{r["rate"]:g}', f'{r["achieved"]:.0f}',
                      f'{r["answered"]:.2f}', *(f'{1e3 * r[k]:.3f}'
                                                for k in ('p50', 'p90', 'p99', 'max')),
                      f'{r["cpu"]:.0f}'])
    return markdown_table(header, table)


def _sweep_section(rows: list, bound: float) -> str:
    header = ['K N/m', 'passivity', 'energy generated J', 'early p-p mm', 'late p-p mm',
              'late/early', 'max F N', 'max penetration mm']
    return markdown_table(header, [
        [f'{r.stiffness:.0f}', r.mode, f'{r.generated_energy:+.3e}',
         _g(1e3 * r.early_amplitude), _g(1e3 * r.late_amplitude), _g(r.decay_ratio),
         _g(r.max_force), _g(1e3 * r.max_penetration)] for r in rows])


def _identical_modes(rows: list) -> str:
    """Say at how many stiffnesses two passivity modes gave exactly the same numbers."""
    def numbers(r):
        return (r.generated_energy, r.early_amplitude, r.late_amplitude, r.max_force,
                r.max_penetration)

    by_key = {(r.mode, r.stiffness): numbers(r) for r in rows}
    stiffnesses = sorted({r.stiffness for r in rows})
    modes = stiffness_sweep.MODES
    notes = []
    for k, a in enumerate(modes):
        for b in modes[k + 1:]:
            same = sum(by_key.get((a, s)) == by_key.get((b, s)) for s in stiffnesses)
            if same:
                notes.append(f'`{a}` and `{b}` give exactly the same numbers at {same} of '
                             f'{len(stiffnesses)} stiffnesses.')
    return ' '.join(notes)


def _extreme_section(rows: list) -> str:
    header = ['case', 'size m', 'points', 'max abs. error m', 'error / size', 'max iterations',
              'statuses', 'FCL: max \\|ours - FCL\\| m', 'FCL disagreements', 'outcome']
    return markdown_table(header, [
        [r.case, _g(r.scale, 2), r.points, _g(r.max_error, 2), _g(r.max_relative_error, 2),
         r.max_iterations, r.statuses, _g(r.fcl_max_discrepancy, 2), r.fcl_disagreements,
         r.outcome] for r in rows])


def _counts_section(recordings: dict) -> str:
    topics = sorted({t for r in recordings.values() for t in r.counts})
    header = ['topic', *(f'{n}: published / recorded' for n in recordings)]
    rows = [[t, *(' / '.join(str(v) if v is not None else '?'
                             for v in r.counts.get(t, (None, None)))
                  for r in recordings.values())] for t in topics]
    return markdown_table(header, rows)


# -- the run ------------------------------------------------------------------------------------

class _Stages:
    """Prints one line as each stage starts and one as it ends, with its duration."""

    def __init__(self, skipped) -> None:
        self.skipped = set(skipped)
        self.count = 0
        self.durations = {}

    def run(self, name: str, title: str, work):
        self.count += 1
        prefix = f'[report] {self.count}/{len(STAGES)} {title}'
        if name in self.skipped:
            print(f'{prefix}: skipped', flush=True)
            return None
        print(f'{prefix} ...', flush=True)
        started = time.monotonic()
        result = work()
        self.durations[name] = time.monotonic() - started
        print(f'[report]     {title}: done in {self.durations[name]:.1f} s', flush=True)
        return result


def _stiff_wall_section(rows: list) -> str:
    return markdown_table(
        ['K N/m', 'device-port controller', 'contacts per tap', 'net work on the tip (mJ)',
         'deepest (mm)', 'peak force (N)', 'poses answered'],
        [[f'{r["stiffness"]:.0f}', 'on' if r['port_passivity'] else 'off',
          f'{r["contacts_per_tap"]:.1f}', f'{1e3 * r["net_work_j"]:+.2f}',
          f'{1e3 * r["max_depth_m"]:.2f}', f'{r["peak_force_n"]:.2f}',
          f'{r["answered_percent"]:.2f} %'] for r in rows])


def _force_effect_section(recordings: dict, demo_dir: Path) -> str:
    """Put the cuboid taps with the force and without it (the demo's control run) side by side."""
    control = demo_dir / NO_FORCE_RUN / 'bag'
    if not control.exists():
        return f'*The demo\'s control run ({NO_FORCE_RUN}) was not found in {demo_dir}.*'
    without = contact_intervals(read_session(control, _typestore()))
    with_force = contact_intervals(recordings['cuboid'].session)
    rows = [[label, len(contacts), _g(1e3 * max(c.max_depth for c in contacts)),
             _g(1e3 * float(np.median([c.max_depth for c in contacts])))]
            for label, contacts in (('rendered force', with_force),
                                    ('force held at zero (control)', without))]
    return ('The same scripted hand taps the cuboid twice: once with the rendered force, once '
            'with it held at zero. The hand aims 10 mm inside the face; the force stops it a '
            'few millimetres in.\n\n' + markdown_table(
                ['cuboid taps', 'contacts', 'deepest (mm)', 'median deepest per tap (mm)'], rows))


def _skipped(what: str) -> str:
    return f'*Skipped in this run ({what}); run without `--skip` to include it.*'


def build(args) -> Path:
    """Run every stage and write the report; returns the README's path."""
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    stages = _Stages(args.skip)
    started = time.monotonic()
    typestore = _typestore()
    recordings = stages.run('bags', 'reading the three bags', lambda: {
        name: read_recording(e, args.demo_dir, typestore) for name, e in EXPERIMENTS.items()})
    truths = stages.run('truth', 'exact ground truth along each recorded trajectory', lambda: {
        name: exact_truth(EXPERIMENTS[name], r.session.tip) for name, r in recordings.items()})
    replays = stages.run('paper', 'the paper\'s method replayed on the same trajectories',
                         lambda: {name: replay_paper(EXPERIMENTS[name], r.session.tip,
                                                     r.velocity)
                                  for name, r in recordings.items()})
    results = {name: measure(recordings[name], truths[name], replays[name])
               for name in recordings}

    def figures():
        for name in recordings:
            experiment_figure(recordings[name], truths[name], replays[name], results[name],
                              out / f'experiment_{name}.png')
        headline_figure(results, out / 'headline.png')

    stages.run('figures', 'figures 1-3 and the headline figure', figures)
    quick = args.quick
    timing = stages.run('timing', 'error against run time, every method', lambda: error_time_rows(
        random=100 if quick else 300, near=100 if quick else 300, tapping=0.4 if quick else 1.0,
        slow_points=60 if quick else 200))
    if timing:
        error_time_figure(timing, out / 'error_vs_time.png')
    tradeoff = stages.run('tradeoff', 'our GJK: tolerance and iteration-cap trade-off',
                          lambda: tradeoff_rows(200 if quick else 600))
    if tradeoff:
        tradeoff_figure(tradeoff, out / 'gjk_tradeoff.png')
    loop = stages.run('loop', 'loop latency over ROS 2 at 0.5, 1, 2 kHz',
                      lambda: loop_rows(3.0 if quick else 5.0, args.domain_id))
    if loop:
        loop_figure(loop, out / 'loop_latency.png')
    sweep = stages.run('sweep', 'stiffness sweep, passivity on and off', stiffness_sweep.sweep)
    bound = _colgate_bound()
    if sweep:
        sweep_figure(sweep, bound, out / 'stiffness_sweep.png')
    stiffwall = stages.run('stiffwall', 'a stiff wall over the real ROS 2 loop', lambda: [
        stiff_wall_loop.run(k, port, duration=4.0 if quick else 6.0, domain_id=args.domain_id)
        for k in STIFF_WALLS for port in (True, False)])
    extreme = stages.run('extreme', 'extreme-geometry table',
                         lambda: extreme_cases.rows(60 if quick else 200))
    text = stages.run('write', 'writing README.md', lambda: _readme(
        recordings, truths, replays, results, timing, tradeoff, loop, sweep, bound, stiffwall,
        extreme, stages, args))
    path = out / 'README.md'
    path.write_text(text)
    print(f'[report] wrote {path} and {len(list(out.glob("*.png")))} figures in '
          f'{time.monotonic() - started:.0f} s', flush=True)
    return path


def _colgate_bound() -> float:
    from force_renderer import passivity_bound, PipelineConfig

    return passivity_bound(stiffness_sweep.DEVICE.damping, PipelineConfig().servo_period,
                           stiffness_sweep.WALL_DAMPING)


def _readme(recordings, truths, replays, results, timing, tradeoff, loop, sweep, bound,
            stiffwall, extreme, stages, args) -> str:
    argv = [str(a) for a in args.argv]
    parts = [
        '# Haptic force feedback: the paper\'s experiments, reproduced and measured',
        '',
        'Generated by `bench/report.py` from the bags `demo` recorded; every number of ours '
        'below is computed by that run. The paper\'s numbers (*A toolkit for haptic force '
        'feedback in a telerobotic ultrasound system*) are typed in from it and labelled '
        '"paper".',
        '', _provenance_section(provenance(), recordings, argv), '',
        '## At a glance', '', _headline_section(recordings, results), '',
        '![headline](headline.png)', '', DEFINITIONS, '',
        '## 1. The paper\'s figures, per experiment', '',
        'Each figure: (a) the paper\'s STL vertices with the recorded tip path; (b) the '
        'distance against time, exact, ours and the paper\'s method, with |error| on a log '
        'axis; (c) the force per axis, ours and the paper\'s law on the same path, and the angle '
        'each makes with the exact outward normal in contact.', '']
    for name in recordings:
        parts += [_experiment_section(recordings[name], replays[name], results[name],
                                      f'experiment_{name}.png'), '']
    parts += ['### The force pushes back', '', _force_effect_section(recordings, args.demo_dir),
              '']
    parts += ['## 2. The paper\'s tables', '']
    for name in recordings:
        table = PAPER[name].table or 'no table in the paper'
        parts += [f'### Contact intervals, {name} ({table})', '',
                  _interval_table(recordings[name], truths[name], replays[name]), '']
    parts += ['### Table 2: the comparison', '', _table_2(results, replays), '',
              'Our scripted operator taps as often as the paper\'s interval tables list (11 on '
              'the hand, 9 on the cuboid) and 9 times on the cylinder; the paper\'s Table 2 '
              'counts 18 collisions on the cuboid.', '',
              '### Table 3: one instant checked by hand', '',
              'The paper checked its force at one instant of the cuboid run; the same check of '
              'ours, at the deepest sample of our cuboid run: K and C per axis from the scene '
              '(160 N/m, 0.8 N·s/m), x from the published closest point and tip, v the '
              'recorded twist. The published force adds the passivity controller\'s damping '
              'and saturation to K x - C v, so a small difference is expected.', '',
              _table_3(recordings['cuboid']), '']
    parts += ['## 3. Error against run time', '']
    if timing:
        parts += [f'Timer overhead (an empty call, included in every time): '
                  f'{bench_collision.timer_overhead():.2f} us median.', '',
                  _error_time_section(timing), '', '![error vs time](error_vs_time.png)', '']
    else:
        parts += [_skipped('error against run time'), '']
    parts += ['### Our GJK: tolerance and iteration cap', '']
    parts += ([_tradeoff_section(tradeoff), '', '![trade-off](gjk_tradeoff.png)', '']
              if tradeoff else [_skipped('GJK trade-off'), ''])
    parts += ['### End-to-end loop latency', '',
              'The real nodes over ROS 2 (the wand tapping the cuboid), one run per layout and '
              'rate; the driver measures each pose\'s round trip to its wrench on one clock.',
              '']
    parts += ([_loop_section(loop), '', '![loop latency](loop_latency.png)', '']
              if loop else [_skipped('loop latency'), ''])
    parts += ['## 4. Numerical stability', '', '### Stiffness sweep', '',
              f'A simulated device pressed into a virtual wall, held and released '
              f'(`bench/stiffness_sweep.py`); the Colgate passivity bound here is '
              f'K = {bound:.0f} N/m.', '']
    parts += ([_sweep_section(sweep, bound), '', _identical_modes(sweep), '',
               '![stiffness sweep](stiffness_sweep.png)', '']
              if sweep else [_skipped('stiffness sweep'), ''])
    parts += ['### A stiff wall over the real ROS 2 loop', '',
              'The sweep above closes the loop in one process with an ideal hold; here the three '
              'nodes run over ROS 2 and the wand feels each force about a millisecond after the '
              'pose it answers (`bench/stiff_wall_loop.py`: the cuboid taps, the renderer\'s '
              'passivity controller on, the driver\'s device-port controller on or off). '
              '*Contacts per tap* above 1 are rebounds; *net work* above 0 is energy the loop '
              'gave the user\'s hand.', '']
    parts += ([_stiff_wall_section(stiffwall), ''] if stiffwall
              else [_skipped('stiff wall over the loop'), ''])
    parts += ['### Extreme geometry', '',
              'Our `collision_engine.distance` against exact truth (`bench/extreme_cases.py`); '
              'FCL\'s answers on the same points through the engine\'s FCL cross-check, in a '
              'child process since FCL can abort. A disagreement is a distance or closest point '
              'beyond FCL\'s own error model plus 1e-9 of the size; on a triangle mesh FCL is '
              'unsigned (magnitudes compared).', '']
    parts += ([_extreme_section(extreme), ''] if extreme else [_skipped('extreme cases'), ''])
    parts += ['## 5. Messages per topic', '',
              'Published (the node\'s own count, from its last diagnostics report) and recorded '
              '(in the bag), per experiment.', '', _counts_section(recordings), '',
              '## Stage times', '',
              ', '.join(f'{k} {v:.1f} s' for k, v in stages.durations.items()), '']
    return '\n'.join(parts)


def main(argv=None) -> int:
    """Write the report; one progress line per stage."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--demo-dir', type=Path, default=ROOT / 'build' / 'demo')
    parser.add_argument('--out', type=Path, default=ROOT / 'report')
    parser.add_argument('--skip', nargs='*', default=[], choices=SKIPPABLE)
    parser.add_argument('--quick', action='store_true', help='fewer points, shorter loop runs')
    parser.add_argument('--domain-id', type=int,
                        default=int(os.environ.get('ROS_DOMAIN_ID', 42)))
    args = parser.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else argv
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    try:
        build(args)
    except FileNotFoundError as error:
        print(f'[report] {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
