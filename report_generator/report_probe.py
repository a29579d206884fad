"""The probe experiments: a linear probe's face swept over a flat slab and the patient phantom.

The demo's ``probe-flat`` and ``probe-phantom`` runs (``simulated_operator.scripts.probe_sweep``:
pressed, rolled +-20 degrees, slid and yawed) are read from their bags. On the flat slab the
torque about the wand's roll axis has an analytic value, that of a continuous face
(``ground_truth.probe_face``). The renderer sums the face at its grid's cell centres instead;
that sum is computed here too, from the scene's tool section, so that the figure separates the
grid's share of the difference from the loop's (the damper's, on a moving wand). Samples whose
force the renderer did not render by the law (zeroed by its watchdog, or saturated to its force
limit, which scales the torque too) are left out of the comparison. Nothing here imports the
renderer.
"""

from dataclasses import dataclass
import math
from pathlib import Path

from ground_truth.probe_face import continuous_face
import numpy as np
from report_generator.report_format import format_number, markdown_table

from collision_engine import read_scene
from haptic_bringup.session import read_session

__all__ = ['FLAT', 'PHANTOM', 'ProbeFindings', 'probe_figure',
           'probe_section', 'read_probe_runs']

FLAT, PHANTOM = 'probe-flat', 'probe-phantom'
FLAT_SCENE = Path(__file__).resolve().parents[1] / 'src' / 'collision_engine' / 'scenes' / \
    'probe_flat.yaml'
MIN_TORQUE = 1e-3  # [N·m] samples below are left out of the relative error
FORCE_LIMIT = 10.0  # [N] the force renderer's default: a force at it was saturated


@dataclass(frozen=True, eq=False)
class ProbeFindings:
    """The two runs' sessions (None when not run) and the flat run's torque comparison.

    ``roll`` (n,) rad, ``rendered``, ``continuous``, ``points`` (n,) N·m: for each flat-run
    sample in contact rendered by the law (module docstring), its roll and the torque about
    the roll axis rendered, of the continuous face and of the face's grid of points.
    ``scene_matches``: the flat run recorded the shipped ``probe_flat.yaml`` that the analytic
    values are computed from.
    """

    scene_matches: bool
    flat: object
    phantom: object
    roll: np.ndarray
    rendered: np.ndarray
    continuous: np.ndarray
    points: np.ndarray


def _grid_face(depth: float, roll: float, rows: np.ndarray, stiffness: float) -> float:
    """Roll torque (N·m) of the face's cell centres ``rows`` (y, m), each at k / their count."""
    pressed = depth - rows * math.sin(roll)
    pressed = np.where(pressed > 0.0, pressed, 0.0)
    return float(stiffness / len(rows) * math.cos(roll) * np.sum(rows * pressed))


def _roll_yaw(quaternions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x, y, z, w = quaternions.T
    return (np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)),
            np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def _about_roll_axis(torque: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    return torque[:, 0] * np.cos(yaw) + torque[:, 1] * np.sin(yaw)


def read_probe_runs(demo_dir: Path, type_store) -> ProbeFindings:
    """Read both probe runs that the demo made and compare the flat run with the analytic face."""
    runs = {}
    for name in (FLAT, PHANTOM):
        bag = demo_dir / name / 'bag'
        runs[name] = read_session(bag, type_store) if bag.is_dir() else None
    flat = runs[FLAT]
    empty = np.zeros(0)
    if flat is None:
        return ProbeFindings(False, None, runs[PHANTOM], empty, empty, empty, empty)
    spec = read_scene(FLAT_SCENE)
    slab = spec.objects[0]
    top = slab.pose.translation[2] + 0.5 * slab.shape.size[2]
    stiffness = float(slab.material.stiffness[2])
    tool = spec.tool
    length = tool.shape.size[1]
    count = max(1, math.ceil(length / tool.face_spacing - 1e-9))
    rows = (np.arange(count) + 0.5) * length / count - 0.5 * length
    roll, yaw = _roll_yaw(flat.orientation)
    force = np.linalg.norm(flat.force, axis=1)
    inside = ((flat.distance < 0.0) & np.all(np.isfinite(flat.torque), axis=1)
              & (force > 0.0) & (force < FORCE_LIMIT * (1.0 - 1e-9)))
    depth = top - flat.tip[inside, 2]
    rolls = roll[inside]
    return ProbeFindings(
        flat.scene == FLAT_SCENE.read_text(), flat, runs[PHANTOM], rolls,
        _about_roll_axis(flat.torque[inside], yaw[inside]),
        np.array([continuous_face(d, r, length, stiffness)[1] for d, r in zip(depth, rolls)]),
        np.array([_grid_face(d, r, rows, stiffness) for d, r in zip(depth, rolls)]))


def probe_section(findings: ProbeFindings) -> str:
    """Write the probe's table: the flat run's roll torque against the analytic face, the runs."""
    if findings.flat is None:
        return ('*Not run: `demo --experiments probe-flat probe-phantom` records the probe '
                'runs.*')
    big = np.abs(findings.continuous) >= MIN_TORQUE

    def errors(reference):
        error = np.abs(findings.rendered - reference)
        relative = error[big] / np.abs(reference[big])
        return [format_number(1e3 * np.median(error)),
                format_number(1e3 * np.percentile(error, 95)),
                format_number(100 * np.median(relative)) if big.any() else '-']
    rows = [['the continuous face (analytic)', *errors(findings.continuous)],
            ['the face\'s grid of points', *errors(findings.points)]]
    lines = [markdown_table(['rendered roll torque against', 'median error (mN·m)',
                             '95th percentile (mN·m)', 'median relative error (%)'], rows), '',
             f'{len(findings.roll)} samples in contact on the flat slab, rendered by the law '
             f'(neither zeroed nor saturated), rolled '
             f'{math.degrees(findings.roll.min()):.1f} to {math.degrees(findings.roll.max()):.1f}'
             f' degrees; relative errors where the analytic torque is at least '
             f'{1e3 * MIN_TORQUE:g} mN·m.'
             + ('' if findings.scene_matches else ' **The run recorded another scene than '
                'the shipped probe_flat.yaml, which these values assume.**'), '']
    for name, session in ((FLAT, findings.flat), (PHANTOM, findings.phantom)):
        if session is None:
            lines.append(f'{name}: not run.')
            continue
        inside = session.distance < 0.0
        roll, yaw = _roll_yaw(session.orientation)
        about_roll = _about_roll_axis(session.torque, yaw)
        lines.append(
            f'{name}: {np.count_nonzero(inside)} of {len(inside)} poses in contact, force up to '
            f'{np.nanmax(np.linalg.norm(session.force, axis=1)):.2f} N, roll torque '
            f'{np.nanmin(about_roll) * 1e3:.1f} to {np.nanmax(about_roll) * 1e3:.1f} mN·m, yaw '
            f'torque within {np.nanmax(np.abs(session.torque[:, 2])) * 1e3:.2f} mN·m.')
    return '\n'.join(lines)


def probe_figure(findings: ProbeFindings, path: Path) -> None:
    """Draw (a) tilt, (b) force and (c) torque against time, and (d) torque against roll."""
    from report_generator.report_figures import _pyplot, _save

    plt = _pyplot()
    figure, axes = plt.subplots(2, 2, figsize=(12.0, 7.5))
    sweep = findings.phantom if findings.phantom is not None else findings.flat
    name = PHANTOM if findings.phantom is not None else FLAT
    roll, yaw = _roll_yaw(sweep.orientation)
    t = sweep.time
    axes[0, 0].plot(t, np.degrees(roll), label='roll')
    axes[0, 0].plot(t, np.degrees(yaw), label='yaw')
    axes[0, 0].set(title=f'(a) {name}: the wand\'s tilt', xlabel='t (s)', ylabel='degrees')
    axes[0, 1].plot(t, sweep.force[:, 2], label='rendered (wand/wrench)')
    axes[0, 1].plot(t, sweep.applied[:, 2], label='applied (servo loop)', alpha=0.7)
    axes[0, 1].set(title='(b) force along z', xlabel='t (s)', ylabel='N')
    axes[1, 0].plot(t, 1e3 * _about_roll_axis(sweep.torque, yaw), label='about roll')
    axes[1, 0].plot(t, 1e3 * sweep.torque[:, 2], label='about yaw (z)')
    axes[1, 0].plot(t, 1e3 * _about_roll_axis(sweep.applied_torque, yaw),
                    label='applied, about roll', alpha=0.7)
    axes[1, 0].set(title='(c) torque about the tip', xlabel='t (s)', ylabel='mN·m')
    order = np.argsort(findings.roll)
    axes[1, 1].plot(np.degrees(findings.roll[order]), 1e3 * findings.continuous[order], 'x',
                    markersize=4, color='C1', label='continuous face (analytic)')
    axes[1, 1].plot(np.degrees(findings.roll), 1e3 * findings.rendered, '.', markersize=1,
                    color='C0', label='rendered')
    axes[1, 1].set(title=f'(d) {FLAT}: roll torque against roll', xlabel='roll (degrees)',
                   ylabel='mN·m')
    for panel in axes.ravel():
        panel.legend(loc='best', fontsize='small')
        panel.grid(alpha=0.3)
    figure.tight_layout()
    _save(figure, path)
