"""The probe's image in the report: the demo's scan as the operator saw it, and its benchmarks.

The demo's telerobotic scan records the B-mode frames where they arrive, at the operator's site
(``/probe/image``, stamped with the TCP pose each shows), and the remote site records its own
F/T sensor and TCP: one clock, as both sites run on this machine. So each frame is shown with
the force the patient felt and where the probe was at its stamp, and its lateness is the
operator's receive time less that stamp, the link's delay included. Two figures: frames along
the scan beside the force, and a strip of frames as the probe first presses in. The image's
stored benchmarks (``bench_image``: a frame's time, the PSF against SIMUS, the speckle;
``imaging_session``: what imaging costs the session) are formatted here as tables.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from report_generator.report_format import markdown_table

from haptic_bringup.session import Frames, read_frames, read_vectors

__all__ = ['ImageScan', 'PRESSURES', 'cost_section', 'frame_time_section', 'image_figures',
           'pressure_frames', 'read_image_scan', 'scan_frames', 'scan_section', 'truth_section',
           'variants_section']

FORCE = '/remote/robot/ft_sensor/wrench'
TCP = '/remote/robot/tcp_pose'
CONTACT = 1.0  # [N] the patient feels the probe
TOUCH = 0.3  # [N] above the F/T sensor's noise (0.16 N at most in air): the probe touches
ALONG = 6  # frames shown along the scan
PRESSURES = (0.5, 2.0, 4.0, 6.0, 8.0)  # [N] the strip's frames: the first at each
BEFORE = 0.25  # [s] the strip's first frame: this long before the probe first touches
SCAN_FIGURE, PRESSURE_FIGURE = 'image_scan.png', 'image_pressure.png'
FRAME_DPI = 60  # [dots per inch] speckle compresses badly: each frame about 110 pixels wide


@dataclass(frozen=True, eq=False)
class ImageScan:
    """The demo scan's frames, with the patient's force and the TCP at each frame's stamp.

    ``time`` (n,) s since the first frame; ``force`` (n,) N, the F/T force's norm; ``tcp``
    (n, 3) m; ``latency`` (n,) s, the operator's receive time less the stamp.
    """

    frames: Frames
    time: np.ndarray
    force: np.ndarray
    tcp: np.ndarray
    latency: np.ndarray


def read_image_scan(demo_dir: Path, typestore) -> ImageScan | None:
    """Return the demo scan's frames and what they show; None if it recorded none."""
    bag = demo_dir / 'teleop' / 'bag'
    if not bag.exists():
        return None
    frames = read_frames(bag, typestore)
    if not len(frames.stamp):
        return None
    series = read_vectors(bag, typestore, {FORCE: 'wrench', TCP: 'pose'}, stamped=True)
    force_t, force = series[FORCE]
    tcp_t, tcp = series[TCP]
    at = frames.stamp
    return ImageScan(frames, at - at[0], np.interp(at, force_t, np.linalg.norm(force, axis=1)),
                     np.column_stack([np.interp(at, tcp_t, tcp[:, axis]) for axis in range(3)]),
                     frames.received - at)


def scan_frames(scan: ImageScan) -> np.ndarray:
    """Return the indices of ``ALONG`` frames spread evenly over the contact."""
    touching = np.flatnonzero(scan.force > CONTACT)
    if not len(touching):
        return np.array([], dtype=int)
    times = np.linspace(scan.time[touching[0]], scan.time[touching[-1]], ALONG)
    return np.searchsorted(scan.time, times).clip(0, len(scan.time) - 1)


def pressure_frames(scan: ImageScan) -> dict:
    """Return pressure → the first frame of the first press at that force or more (N → index).

    Before them, under 0 N, the frame ``BEFORE`` s before the probe first touches (``TOUCH``).
    """
    touching = np.flatnonzero(scan.force > TOUCH)
    if not len(touching):
        return {}
    first = touching[0]
    shown = {0.0: max(np.searchsorted(scan.time, scan.time[first] - BEFORE) - 1, 0)}
    for pressure in PRESSURES:
        reached = np.flatnonzero(scan.force[first:] >= pressure)
        if len(reached):
            shown[pressure] = first + reached[0]
    return shown


def _frame_panel(axes, scan: ImageScan, index: int) -> None:
    axes.imshow(scan.frames.images[index], cmap='gray', vmin=0, vmax=255)
    axes.set_title(f't {scan.time[index]:.1f} s, {scan.force[index]:.1f} N\n'
                   f'x {1e3 * scan.tcp[index, 0]:+.0f} mm, z {1e3 * scan.tcp[index, 2]:.0f} mm',
                   fontsize=8)
    axes.set_xticks([])
    axes.set_yticks([])


def image_figures(scan: ImageScan, out: Path) -> list[str]:
    """Draw the scan's figure and the pressure strip into ``out``; return their file names."""
    from report_generator.report_figures import _pyplot, _save

    plt = _pyplot()
    along, pressed = scan_frames(scan), pressure_frames(scan)
    drawn = []
    if len(along):
        figure = plt.figure(figsize=(11.0, 5.6), dpi=FRAME_DPI)
        grid = figure.add_gridspec(2, ALONG, height_ratios=(1.0, 0.8))
        for column, index in enumerate(along):
            _frame_panel(figure.add_subplot(grid[0, column]), scan, index)
        force_axes = figure.add_subplot(grid[1, :])
        force_axes.plot(scan.time, scan.force, c='C3', lw=1.0, label='patient force (F/T), N')
        brightness = scan.frames.images.reshape(len(scan.time), -1).mean(axis=1)
        force_axes.plot(scan.time, brightness / 10.0, c='C0', lw=1.0,
                        label='image mean grey level / 10')
        force_axes.vlines(scan.time[along], 0.0, scan.force.max(), colors='k', lw=0.6,
                          linestyles=':', label='frames shown')
        force_axes.set(xlabel='time of the frame\'s pose since the first frame, s')
        force_axes.legend(fontsize=8, loc='upper right')
        figure.tight_layout()
        _save(figure, out / SCAN_FIGURE)
        drawn.append(SCAN_FIGURE)
    if pressed:
        figure, panels = plt.subplots(1, len(pressed), figsize=(11.0, 2.6), dpi=FRAME_DPI)
        for axes, index in zip(np.atleast_1d(panels), pressed.values()):
            _frame_panel(axes, scan, index)
        figure.tight_layout()
        _save(figure, out / PRESSURE_FIGURE)
        drawn.append(PRESSURE_FIGURE)
    return drawn


def scan_section(scan: ImageScan, delay: float) -> str:
    """Return the demo scan's frames as the operator got them: how many, how often, how late."""
    frames = scan.frames
    period = np.diff(frames.stamp)
    height, width = frames.images.shape[1:]
    return '\n'.join([
        f'{len(frames.stamp)} frames of {width} x {height} mono8 in '
        f'`{", ".join(sorted(frames.frame_ids))}`, {1.0 / np.median(period):.1f} a second '
        f'(the longest gap {1e3 * period.max():.0f} ms); {np.mean(scan.force > CONTACT):.0%} '
        f'of them with the probe on the patient. From the pose each shows to its arrival in '
        f'the operator\'s bag: p50 {1e3 * np.median(scan.latency):.0f} ms, p99 '
        f'{1e3 * np.percentile(scan.latency, 99):.0f} ms, over a link of '
        f'{1e3 * delay:.0f} ms one way (target: p99 <= {50 + 1e3 * delay:.0f} ms).'])


def frame_time_section(results: dict) -> str:
    """Return a frame's time on one core, per probe, as shares of the 30 Hz frame period."""
    rows = [[name, f'{r["median_ms"]:.2f} / {r["p99_ms"]:.2f}',
             f'{r["median_share"]:.3f} / {r["p99_share"]:.3f}',
             f'{r["cpu_median_ms"]:.2f} / {r["cpu_p99_ms"]:.2f}',
             f'{r["cpu_median_share"]:.3f} / {r["cpu_p99_share"]:.3f}',
             f'{r["frame_over_floor"]:.1f}', f'{r["frames_per_second_one_core"]:.0f}']
            for name, r in results['frame'].items()]
    return markdown_table(['probe', 'wall ms, median / p99', 'share of 1/30 s',
                           'CPU ms, median / p99', 'share of 1/30 s', 'CPU / display floor',
                           'frames/s, one core'], rows)


def truth_section(results: dict) -> str:
    """Return the PSF against SIMUS's and the speckle against Rayleigh's, as tables."""
    parts = []
    if results.get('psf'):
        parts += [markdown_table(
            ['probe', 'fc MHz', 'cycles', 'axis', 'model FWHM mm', 'SIMUS FWHM mm', 'error'],
            [[r['probe'], f'{r["fc_mhz"]:.2f}', f'{r["cycles"]:g}', r['axis'],
              f'{r["model_mm"]:.3f}', f'{r["simus_mm"]:.3f}', f'{r["error"]:+.1%}']
             for r in results['psf']]), '']
    parts.append(markdown_table(
        ['fc MHz', 'samples', 'envelope mean / std', 'Rayleigh', 'error'],
        [[f'{r["fc_mhz"]:.1f}', str(r['samples']), f'{r["mean_over_std"]:.3f}',
          f'{r["rayleigh"]:.3f}', f'{r["error"]:+.1%}'] for r in results['speckle']]))
    return '\n'.join(parts)


STREAMS = {'operator_rate_hz': ('operator\'s poses a second', 'rate'),
           'operator_answered_percent': ('operator\'s poses answered', 'answered'),
           'operator_round_trip_p99_s': ('operator\'s round trip, p99', 'p99'),
           'robot_rate_hz': ('robot\'s ticks a second', 'rate'),
           'robot_tick_p99_s': ('robot\'s tick, p99', 'p99'),
           'commands_hz': ('commands reaching the robot a second', 'rate'),
           'feedback_hz': ('feedback reaching the operator a second', 'rate')}


def _yielding(variant: str) -> str:
    """Say how the imager's process yields the cores (``imaging_session.imager_parameters``)."""
    return ('its frame thread under SCHED_IDLE (it runs on what every other process leaves)'
            if variant == 'idle' else f'its frame thread at niceness +{variant}')


def _loops(priority: int) -> str:
    """Say how the loops' processes are scheduled (``haptic_util.priority``)."""
    return (f'every thread of the loops\' processes under SCHED_FIFO at priority {priority}'
            if priority else 'the loops\' processes at normal scheduling')


def _hogs(count: int) -> str:
    return (f'with {count} other process{"es" if count > 1 else ""} keeping '
            f'{"a core" if count == 1 else f"{count} cores"} busy throughout' if count
            else 'with no other process keeping a core busy')


def _met(ratio: float, bound: float, kind: str) -> bool:
    return ratio <= bound if kind == 'p99' else ratio >= bound


def _verdict(ratio: float, low: float, high: float, bound: float, kind: str) -> str:
    """Say whether the target is met: by every group, by the median only, or not."""
    if not _met(ratio, bound, kind):
        return 'MISSED'
    every = _met(low, bound, kind) and _met(high, bound, kind)
    return 'met' if every else 'met by the median only'


def cost_section(results: dict) -> str:
    """Return what imaging costs the telerobotic session: ratios on / off, CPU, pose to image."""
    summary, variant = results['summary'], results['variant']
    priority = results['thread_priority']
    ratios, ranges, targets = summary['ratios'], summary['ranges'], summary['targets']
    runs = [r for r in results['rows'] if r['thread_priority'] == priority]
    rows = []
    for key, (label, kind) in STREAMS.items():
        on = np.median([r[key] for r in runs if r['variant'] == variant])
        off = np.median([r[key] for r in runs if not r['imaging']])
        scale, unit = (1e3, ' ms') if key.endswith('_s') else (1.0, '')
        bound = targets[kind]
        low, high = ranges[key]
        rows.append([label, f'{scale * off:.2f}{unit}', f'{scale * on:.2f}{unit}',
                     f'{ratios[key]:.3f} [{low:.2f}-{high:.2f}]',
                     f'{"<=" if kind == "p99" else ">="} {bound:g} '
                     f'({_verdict(ratios[key], low, high, bound, kind)})'])
    loads = [r['load'] for r in results['rows']]
    delay = summary['delay_s']
    return '\n'.join([
        markdown_table(['stream', 'imaging off', 'on', 'on / off [range]', 'target'], rows), '',
        f'{summary["pairs"]} groups of runs, imaging off and on side by side, '
        f'{_hogs(results["hogs"])}; the figures on and '
        f'off are medians over the runs, each ratio is taken within a group, its median and '
        f'range over the groups given. The load average was {min(loads):.1f}-{max(loads):.1f} '
        f'(other jobs on the machine): where a ratio\'s range spans its target both ways, the '
        f'runs vary more with that load than with imaging. The imager is a process of its own '
        f'at the remote site, {_yielding(variant)}; {_loops(priority)}. The '
        f'session\'s processes used {summary["cpu_off_percent"]:.0f} % of a core without '
        f'imaging and {summary["cpu_on_percent"]:.0f} % with it: imaging adds '
        f'{summary["cpu_added_percent"]:.0f} % at {summary["frames_hz"]:.1f} frames a second, '
        f'{1e3 * summary["cpu_per_frame_s"]:.1f} ms of CPU a frame (the imaging thread\'s own, '
        f'median: {1e3 * summary["frame_cpu_p50_s"]:.1f} ms). Pose to image, p99: '
        f'{1e3 * summary["pose_to_image_p99_s"]:.0f} ms at the operator over the '
        f'{1e3 * delay:.0f} ms link (target {50 + 1e3 * delay:.0f} ms), '
        f'{1e3 * summary["pose_to_publication_p99_s"]:.0f} ms to its publication at the remote '
        f'site.', *variants_section(results)])


def variants_section(results: dict) -> list:
    """Return how each way of sharing the cores did, beside imaging off in the same groups.

    Each is named as ``imaging_session.label`` names it.
    """
    variants = results.get('variants', {})
    if len(variants) < 2:
        return []
    keys = ('operator_rate_hz', 'robot_rate_hz', 'robot_tick_p99_s', 'commands_hz')
    rows = [[name,
             *(f'{v["ratios"][k]:.3f}' for k in keys), f'{v["frames_hz"]:.1f}',
             f'{1e3 * v["pose_to_image_p99_s"]:.0f} ms'] for name, v in variants.items()]
    return ['', 'Each way of sharing the cores, on / off within the same groups:', '',
            markdown_table(['cores', *(STREAMS[k][0] for k in keys), 'frames a second',
                            'pose to image, p99'], rows)]
