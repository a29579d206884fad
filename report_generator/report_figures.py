"""The report's figures: the paper's Figures 1-3 reproduced, and one figure per measured table.

Each function draws one PNG from the arrays and rows the other report modules compute; none
measures anything itself.
"""

import io
from pathlib import Path

from bench import stiffness_sweep
import numpy as np
from report_generator.report_experiments import EXPERIMENTS, PAPER
from report_generator.report_format import format_length
from report_generator.report_metrics import angle_stats, FALSE_ERROR, FELT_FORCE, Measures
from report_generator.report_paper_replay import PaperReplay
from report_generator.report_recordings import Recording
from report_generator.report_truth import Truth

__all__ = ['ERROR_FLOOR', 'error_time_figure', 'experiment_figure', 'headline_figure',
           'sweep_figure', 'tradeoff_figure']

ERROR_FLOOR = 1e-18  # [m] log axes draw smaller errors (exact to rounding) here
DPI = 90  # [dots per inch] with the figure sizes below, 700-1400 pixels wide
PALETTE_COLOURS = 256


def _pyplot():
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    return plt


def _save(figure, path: Path) -> None:
    """Write the figure as a compact PNG (a palette of 256 colours, no dithering) and free it.

    The report's PNGs are committed beside its README; line plots use few colours, so the
    palette keeps them sharp at a fraction of the size of full colour.
    """
    from PIL import Image

    rendered = io.BytesIO()
    figure.savefig(rendered, format='png', dpi=DPI)
    _pyplot().close(figure)
    with Image.open(rendered) as image:
        palette = image.convert('RGB').quantize(PALETTE_COLOURS, dither=Image.Dither.NONE)
    palette.save(path, optimize=True)


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
    _save(figure, path)


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
        axes.plot(session.time, session.applied[:, axis], c=f'C{axis}', lw=1.0,
                  label=f'F{label} ours, applied')
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
        left.bar_label(drawn, labels=[format_length(v) for v in values], fontsize=6, rotation=90,
                       padding=2)
    left.set_yscale('log')
    left.set_xticks(x, names)
    left.set_ylabel(f'|distance error| m (< {ERROR_FLOOR:g} drawn at it)')
    left.set_ylim(ERROR_FLOOR / 10, 10.0)
    left.set_title('distance error')
    left.legend(fontsize=7, loc='upper left', bbox_to_anchor=(0.0, -0.08), ncol=2)
    for k, (label, colour) in enumerate((('ours', 'C0'), ('paper\'s law', 'C1'))):
        stats = [angle_stats(results[n].ours_angles if k == 0 else results[n].paper_angles)
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
    _save(figure, path)


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
    _save(figure, path)


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
    _save(figure, path)


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
    _save(figure, path)


def teleop_figure(traces: dict, scale: float, path: Path) -> None:
    """Felt force / scale and the patient's force against time, a panel per titled series."""
    plt = _pyplot()
    figure, panels = plt.subplots(len(traces), 1, figsize=(11, 2.6 * len(traces)), sharex=True,
                                  constrained_layout=True)
    for axes, (title, series) in zip(np.atleast_1d(panels), traces.items()):
        start = series['/wand/pose'][0][0]
        felt_t, felt = series['/wand/applied_wrench']
        patient_t, patient = series['/remote/robot/ft_sensor/wrench']
        axes.plot(patient_t - start, patient[:, 2], c='C3', lw=0.8,
                  label='patient (F/T sensor, z)')
        axes.plot(felt_t - start, felt[:, 2] / scale, c='C0', lw=0.8,
                  label=f'felt by the hand / {scale:g} (applied, z)')
        axes.set_ylabel('force, N')
        axes.set_title(title)
        axes.legend(fontsize=8, loc='upper right')
    np.atleast_1d(panels)[-1].set_xlabel('time since the first wand pose, s')
    _save(figure, path)
