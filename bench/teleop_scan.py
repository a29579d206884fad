"""The telerobotic scan over the emulated link: each bilateral scheme at each one-way delay.

    .venv/bin/python bench/teleop_scan.py [--schemes direct tdpa model]
        [--delays 0 0.01 0.025 0.05 0.1 0.25 0.5] [--jitter 0.2] [--loss 0.05]
        [--site-streams in-process dds] [--model-step-rates 5 0] [--delay-trace CSV]
        [--measured-link FROM ...] [--force-hold] [--keep DIR] [--json PATH]

Both sites run as real processes in two DDS domains, joined by the two site gateways
(``haptic_loop --teleop``): the scripted sonographer approaches the patient phantom, presses,
sweeps along it at about 8 N and lifts. Every figure comes from the bag, from what the device
applied to the hand (``/wand/applied_wrench``) and what the remote site's sensor measured
(``/remote/robot/ft_sensor/wrench``), on the machine's one clock:

- **net work** of the applied force on the hand (> 0: the link gave the operator energy), and
  the **oscillation**: the RMS of the felt force about its own 0.25 s moving mean while in
  contact, as a % of the mean felt force. Stable: net work ≤ 0 and oscillation ≤ 10 %;
- **transparency**: the RMS of felt / force_scale − patient force, at the lag (within the round
  trip and 200 ms) that makes it least, in N and as a % of the mean patient force in contact;
- **peak patient force**, against ``max_patient_force``;
- **tracking**: the RMS of the TCP against the wand's path (scale 1), at its best lag;
- **smoothness** (issue 28): in steady contact (patient force > 3 N), the change of the felt
  force / force_scale between consecutive 1 ms ticks against the same for the patient's force,
  as the ratio of their 99th percentiles and of their largest, and the count of felt **jumps**
  over 1 N. Smooth: both ratios ≤ 3 and no jump. A sonographer reads the tissue by differences
  of a few tenths of a newton; a step the patient's force does not make is a jolt;
- the patient's **force rise** (issue 28's envelope): the time from the first contact to 90 % of
  the mean contact force, and the peak rate of rise of the patient's force over 5 ms;
- the **force error** through the sweep (from 0.5 s after it begins, ``SWEEP`` from the
  session's start, the driver's ``wand/session_start``): the patient's force against its own
  mean (what the operator's hand keeps by itself); in a hold run, against the held one, from
  0.5 s after the hold reached the remote site to its release's arrival there (both read from
  the remote site's bag: the link's delay is not the regulator's settling).

The jitter is given as a fraction of the delay (20 %, and 5 % loss: issue 28's harsher link, to
500 ms one way). ``--delay-trace`` runs each scheme once more over a measured link: a CSV of
one-way delays (``time,delay`` in s, ``link_emulator.link.DelayTrace``), with no jitter added
(the trace has its own) and the same loss. ``--measured-link`` does so over the measured
intercontinental link that ships with the project (``measured_link``: echo round trips between
Argentina and Málaga), replayed from each FROM s into it; over each trace ``model`` runs once
more with both ends' watchdogs and admission bounds fixed at the nodes' defaults (``fixed bounds
(before)``), not widened to the link's spread as the launcher now does. Each site is one
process; its nodes hand their streams over in the process (``in-process``, the default) or
through DDS (``dds``: the sites before intra-process delivery, their CPU's baseline). With both,
each case runs once per way, one after the other. With ``--json`` the figure of the felt and
the patient's force against time at 100 and 500 ms, a panel per scheme and delay, is drawn beside
the file (.png).
``--model-step-rates`` runs ``model`` once per rate of the driver's easing of new models (N/s;
0: each at once, the baseline), the rows marked ``ease N``. ``--force-hold`` runs ``model`` once
more per delay with the remote site holding ``HOLD_FORCE`` through the sweep: the operator's
site asks on ``teleop/hold`` as the sweep begins and releases as it ends, across the gateways.
"""
import argparse
import concurrent.futures
import itertools
import math
import pathlib
import shutil
import sys
import tempfile
import time

from bench import machine, result_files, ros_domain
from bench.measured_link import echo_delays
import numpy as np
import psutil

from haptic_bringup.bag import typestore_with
from haptic_bringup.hold_request import hold_during
from haptic_bringup.launcher import LINK_TIMEOUT, Loop, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import read_numbers, read_session_start, read_vectors
from haptic_contract.graph import absolute, REMOTE_PREFIX, TELEOP_HOLD
from link_emulator.link import DelayTrace
from teleop_protocol.admission import AdmissionConfig

__all__ = ['figures', 'felt_steps', 'hold_error', 'read_scan', 'run', 'main']

FORCE_SCALE = 0.3  # the leader's default: felt = 0.3 x patient
CONTACT = 1.0  # [N] patient force above which the probe is in contact
GRID = 1e-3  # [s]
MEAN_WINDOW = 0.25  # [s] the felt force's own slow part
STABLE_OSCILLATION = 10.0  # [%] of the mean felt force
LAG_MARGIN = 0.2  # [s] the robot's own lag behind its target (its impedance, its speed limit)
FIGURE_DELAYS = (0.1, 0.5)  # [s] the delays whose runs are drawn with --json
STEADY_CONTACT = 3.0  # [N] patient force above which the smoothness is judged
JUMP = 1.0  # [N] a change of the felt force (scaled) between ticks that counts as a jolt
SMOOTH_RATIO = 3.0  # the felt force's steps at most this many times the patient's
RISE_WINDOW = 5e-3  # [s] the patient's rate of rise, over the F/T sensor's noise
CPU_WINDOW = (3.0, 15.0)  # [s] after the session closed: the press and the sweep
SWEEP = (5.0, 16.0)  # [s] from the session's start: the scan's sweep along the patient (scan.yaml)
HOLD_SETTLE = 0.5  # [s] after the sweep begins, or the hold arrives, before the error counts
HOLD_FORCE = 8.0  # [N] held in a hold run: the scan's own press
_FIXED = {'link_timeout': LINK_TIMEOUT, 'max_stamp_lead': AdmissionConfig.max_lead}
FIXED_BOUNDS = {  # the nodes' own defaults: the bounds before they followed the link's spread
    'teleop_leader': {**_FIXED, 'max_feedback_age': AdmissionConfig.max_age},
    'teleop_follower': {**_FIXED, 'max_command_age': AdmissionConfig.max_age}}
SCAN_LIMIT = 60.0  # [s] a scan ends within this, or it failed: the span of a trace it replays
SITE_STREAMS = ('in-process', 'dds')
TOPICS = {'/wand/pose': 'pose', '/wand/applied_wrench': 'wrench',
          '/remote/robot/ft_sensor/wrench': 'wrench', '/remote/robot/tcp_pose': 'pose'}
REMOTE_HOLD = REMOTE_PREFIX + absolute(TELEOP_HOLD)


def read_scan(path: pathlib.Path) -> dict:
    """Topic → (receive times s, (n, 3) vectors) for the four streams the figures need."""
    return read_vectors(path, typestore_with(custom_definitions()), TOPICS)


def _on_grid(times: np.ndarray, values: np.ndarray, grid: np.ndarray) -> np.ndarray:
    return np.stack([np.interp(grid, times, values[:, axis]) for axis in range(3)], axis=1)


def _best_lag(a: np.ndarray, b: np.ndarray, longest: float, mask: np.ndarray):
    """Return the least RMS of |a(t) − b(t + lag)| over ``mask``, for lags within ±``longest``."""
    best = (np.inf, 0.0)
    for shift in range(-round(longest / GRID), round(longest / GRID) + 1):
        shifted = np.roll(b, -shift, axis=0)
        valid = mask.copy()
        if shift > 0:
            valid[-shift:] = False
        elif shift < 0:
            valid[:-shift] = False
        error = np.sqrt(np.mean(np.sum((a[valid] - shifted[valid]) ** 2, axis=1)))
        best = min(best, (error, shift * GRID))
    return best


def felt_steps(felt: np.ndarray, patient: np.ndarray) -> dict:
    """Return the felt force's (scaled) steps against the patient's, (n, 3) N on the 1 ms grid.

    Only the ticks whose both ends are in steady contact count.
    """
    steady = np.linalg.norm(patient, axis=1) > STEADY_CONTACT
    steady = steady[1:] & steady[:-1]
    if not steady.any():
        return {'step_ratio_p99': np.nan, 'step_ratio_max': np.nan, 'felt_step_max_n': np.nan,
                'patient_step_max_n': np.nan, 'jumps': 0, 'smooth': False}
    felt_step = np.linalg.norm(np.diff(felt, axis=0), axis=1)[steady]
    patient_step = np.linalg.norm(np.diff(patient, axis=0), axis=1)[steady]
    p99 = float(np.percentile(felt_step, 99)) / float(np.percentile(patient_step, 99))
    largest = float(felt_step.max()) / float(patient_step.max())
    jumps = int(np.count_nonzero(felt_step > JUMP))
    return {'step_ratio_p99': p99, 'step_ratio_max': largest,
            'felt_step_max_n': float(felt_step.max()),
            'patient_step_max_n': float(patient_step.max()), 'jumps': jumps,
            'smooth': max(p99, largest) <= SMOOTH_RATIO and jumps == 0}


def force_rise(patient: np.ndarray, mean_contact: float) -> dict:
    """Return the time (s) from first contact to 90 % of ``mean_contact`` and the peak rate.

    ``patient`` is (n, 3) N on the 1 ms grid; the rate (N/s) is over ``RISE_WINDOW``.
    """
    norm = np.linalg.norm(patient, axis=1)
    steps = round(RISE_WINDOW / GRID)
    rate = float(np.max(norm[steps:] - norm[:-steps])) / RISE_WINDOW if len(norm) > steps else 0.0
    touched = np.flatnonzero(norm > CONTACT)
    if not touched.size or mean_contact <= 0.0:
        return {'time_to_force_s': np.nan, 'peak_rise_n_per_s': rate}
    reached = np.flatnonzero(norm[touched[0]:] >= 0.9 * mean_contact)
    return {'time_to_force_s': float(reached[0]) * GRID if reached.size else np.nan,
            'peak_rise_n_per_s': rate}


def held_window(path: pathlib.Path) -> tuple:
    """Return when (s) the hold reached the remote site and its release did (inf: none)."""
    times, forces = read_numbers(path, typestore_with(custom_definitions()), REMOTE_HOLD)
    held = np.flatnonzero(forces > 0.0)
    if not held.size:
        raise RuntimeError(f'{path}: no hold reached the remote site ({REMOTE_HOLD} is empty)')
    released = np.flatnonzero((forces == 0.0) & (times > times[held[0]]))
    return float(times[held[0]]), float(times[released[0]]) if released.size else math.inf


def hold_error(times: np.ndarray, patient: np.ndarray, held: float, start: float,
               end: float) -> dict:
    """Return the patient's force (N) against ``held`` from ``HOLD_SETTLE`` after ``start``.

    ``held`` NaN: against the force's own mean over the same window.
    """
    window = (times >= start + HOLD_SETTLE) & (times < end)
    force = np.linalg.norm(patient[window], axis=1)
    held = held if np.isfinite(held) else float(np.mean(force))
    error = force - held
    return {'held_n': held, 'hold_error_max_n': float(np.max(np.abs(error))),
            'hold_error_rms_n': float(np.sqrt(np.mean(error ** 2)))}


def figures(scan: dict, delay: float, force_scale: float = FORCE_SCALE) -> dict:
    """Compute what the module's docstring lists from the series ``read_scan`` returns."""
    pose_t, pose = scan['/wand/pose']
    felt_t, felt = scan['/wand/applied_wrench']
    patient_t, patient = scan['/remote/robot/ft_sensor/wrench']
    tcp_t, tcp = scan['/remote/robot/tcp_pose']
    grid = np.arange(max(pose_t[0], patient_t[0]), min(pose_t[-1], patient_t[-1]), GRID)
    wand, felt_grid = _on_grid(pose_t, pose, grid), _on_grid(felt_t, felt, grid)
    patient_grid, tcp_grid = _on_grid(patient_t, patient, grid), _on_grid(tcp_t, tcp, grid)
    # Each tick's applied force is published with its pose; the recorder may miss either.
    felt_at_pose = _on_grid(felt_t, felt, pose_t)
    work = float(np.sum(np.einsum('ij,ij->i', felt_at_pose[1:], np.diff(pose, axis=0))))
    contact = np.linalg.norm(patient_grid, axis=1) > CONTACT
    window = np.ones(round(MEAN_WINDOW / GRID)) / round(MEAN_WINDOW / GRID)
    felt_norm = np.linalg.norm(felt_grid, axis=1)
    wobble = felt_norm - np.convolve(felt_norm, window, mode='same')
    felt_mean = float(np.mean(felt_norm[contact])) if contact.any() else 0.0
    oscillation = (100.0 * float(np.sqrt(np.mean(wobble[contact] ** 2))) / felt_mean
                   if felt_mean > 0.0 else 0.0)
    longest = 2.0 * delay + LAG_MARGIN
    tracking, _ = _best_lag(wand, tcp_grid, longest, np.ones_like(contact))
    error, lag, mean_patient = np.nan, np.nan, 0.0  # no contact, nothing to compare
    if contact.any():
        error, lag = _best_lag(felt_grid / force_scale, patient_grid, longest, contact)
        mean_patient = float(np.mean(np.linalg.norm(patient_grid[contact], axis=1)))
    return {'delay': delay, 'net_work_j': work, 'oscillation_percent': oscillation,
            'stable': work <= 0.0 and oscillation <= STABLE_OSCILLATION,
            'transparency_n': error,
            'transparency_percent': 100.0 * error / mean_patient if mean_patient else np.nan,
            'lag_s': lag, 'mean_patient_n': mean_patient,
            'peak_patient_n': float(np.max(np.linalg.norm(patient, axis=1))),
            'tracking_m': tracking, 'contact_s': float(contact.sum() * GRID),
            **felt_steps(felt_grid / force_scale, patient_grid),
            **force_rise(patient_grid, mean_patient)}


def run(scheme: str, delay: float, *, jitter: float = 0.2, loss: float = 0.05,
        domain_id: int = 42, keep: pathlib.Path | None = None,
        site_streams: str = 'in-process', model_step_rate: float | None = None,
        delay_trace: pathlib.Path | None = None, hold: float | None = None,
        fixed_bounds: bool = False) -> dict:
    """One scan with ``scheme`` over a link of one-way ``delay`` s; its figures.

    ``model_step_rate``: the driver's (N/s), None for the launcher's. ``delay_trace``: a CSV of
    one-way delays replayed instead of ``delay``, which is then the trace's longest. ``hold``:
    the force (N) the remote site is asked to hold through the sweep. ``fixed_bounds``: both
    ends' watchdogs and admission at their nodes' defaults, not widened to the link's spread
    (the code before it).
    """
    with tempfile.TemporaryDirectory() as tmp:
        folder = keep or pathlib.Path(tmp)
        shutil.rmtree(folder / 'bag', ignore_errors=True)  # an earlier run's
        config = LoopConfig(record=str(folder / 'bag'), domain_id=domain_id,
                            run_dir=folder / 'launch', teleop=scheme,
                            link={'delay': delay, 'jitter': jitter * delay, 'loss': loss,
                                  **({'delay_trace': str(delay_trace)} if delay_trace else {})},
                            intra_process=site_streams == 'in-process',
                            overrides={**({} if model_step_rate is None else
                                          {'wand_driver': {'model_step_rate': model_step_rate}}),
                                       **(FIXED_BOUNDS if fixed_bounds else {})})
        with concurrent.futures.ThreadPoolExecutor(1) as requests:
            asked = None if hold is None else requests.submit(hold_during, domain_id, hold,
                                                              *SWEEP, 120.0)
            with Loop(config) as loop:
                cpu = process_cpu(loop)
                if loop.wait(SCAN_LIMIT) is None:
                    raise RuntimeError(f'{scheme} at {delay} s: the scan did not end')
            if asked is not None and asked.result() is None:
                raise RuntimeError(f'{scheme} at {delay} s: the hold was never asked')
        streams = ', '.join([site_streams] + ([] if model_step_rate is None else
                                              [f'ease {model_step_rate:g}'])
                            + ([] if delay_trace is None else [f'trace {delay_trace.name}'])
                            + ([] if hold is None else [f'force held {hold:g} N'])
                            + (['fixed bounds (before)'] if fixed_bounds else []))
        scan = read_scan(folder / 'bag')
        start = read_session_start(folder / 'bag', typestore_with(custom_definitions()))
        window = (start + SWEEP[0], start + SWEEP[1]) if hold is None else \
            held_window(folder / 'bag')
        return {'scheme': scheme, **figures(scan, delay), 'cpu': cpu, 'site_streams': streams,
                **hold_error(*scan['/remote/robot/ft_sensor/wrench'],
                             np.nan if hold is None else hold, *window)}


def process_cpu(loop: Loop) -> dict:
    """Process → CPU (% of one core) over the scan's steady middle: its press and sweep."""
    processes = {child.name: psutil.Process(child.pid) for child in loop.children}
    time.sleep(CPU_WINDOW[0])
    before = {name: _cpu_seconds(p) for name, p in processes.items()}
    time.sleep(CPU_WINDOW[1] - CPU_WINDOW[0])
    return {name: 100.0 * (_cpu_seconds(p) - before[name]) / (CPU_WINDOW[1] - CPU_WINDOW[0])
            for name, p in processes.items()}


def _cpu_seconds(process: psutil.Process) -> float:
    """Return the CPU time (s) of ``process`` and its threads so far."""
    times = process.cpu_times()
    return times.user + times.system


def print_header() -> None:
    print(f'{"scheme":>6} {"ms":>6} {"stable":>6} {"work mJ":>9} {"osc %":>6} '
          f'{"err N":>7} {"err %":>6} {"peak N":>7} {"track mm":>8} {"step p99":>8} '
          f'{"step max":>8} {"jumps":>5} {"rise s":>6} {"N/s":>5}')


def print_row(r: dict) -> None:
    print(f'{r["scheme"]:>6} {1e3 * r["delay"]:6.0f} {"yes" if r["stable"] else "NO":>6} '
          f'{1e3 * r["net_work_j"]:9.1f} {r["oscillation_percent"]:6.1f} '
          f'{r["transparency_n"]:7.2f} {r["transparency_percent"]:6.1f} '
          f'{r["peak_patient_n"]:7.2f} {1e3 * r["tracking_m"]:8.2f} {r["step_ratio_p99"]:8.1f} '
          f'{r["step_ratio_max"]:8.1f} {r["jumps"]:5d} {r["time_to_force_s"]:6.2f} '
          f'{r["peak_rise_n_per_s"]:5.0f} {r.get("site_streams", "")}',
          flush=True)


def print_hold_errors(rows: list) -> None:
    print("\nThe patient's force through the sweep against the held one (unheld: its mean):")
    for r in rows:
        if r['scheme'] == 'model':
            print(f'{1e3 * r["delay"]:6.0f} ms {r["site_streams"]:>30} held {r["held_n"]:5.2f} N'
                  f'  error max {r["hold_error_max_n"]:5.2f} N'
                  f'  rms {r["hold_error_rms_n"]:5.2f} N')


def measured_traces(delay_trace: pathlib.Path | None, starts: list,
                    folder: pathlib.Path) -> list:
    """Return the CSVs of delays to replay: the one given, then the shipped link from each."""
    shipped, echo = [], echo_delays() if starts else None
    for start in starts:
        shipped.append(folder / f'argentina_malaga_from_{start:g}s.csv')
        echo.after(start, SCAN_LIMIT).to_csv(shipped[-1])
    return ([delay_trace] if delay_trace else []) + shipped


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--schemes', nargs='+', default=['direct', 'tdpa', 'model'],
                        choices=['direct', 'tdpa', 'model'])
    parser.add_argument('--delays', nargs='+', type=float,
                        default=[0.0, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5])
    parser.add_argument('--jitter', type=float, default=0.2, help='fraction of the delay')
    parser.add_argument('--loss', type=float, default=0.05)
    parser.add_argument('--delay-trace', type=pathlib.Path, metavar='CSV',
                        help='each scheme once more over these measured one-way delays')
    parser.add_argument('--measured-link', nargs='+', type=float, default=[], metavar='FROM',
                        help='each scheme once more over the Argentina-Malaga trace, from FROM s')
    parser.add_argument('--site-streams', nargs='+', default=['in-process'],
                        choices=SITE_STREAMS, help="how each site's nodes pass their streams")
    parser.add_argument('--model-step-rates', nargs='+', type=float, default=[None],
                        help="model: the driver's easing of new models, N/s (0: at once)")
    parser.add_argument('--keep', type=pathlib.Path, help="keep each case's bag under here")
    parser.add_argument('--force-hold', action='store_true',
                        help=f'model once more per delay, {HOLD_FORCE:g} N held through the sweep')
    ros_domain.add_option(parser)
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy")}')
    print_header()
    rows, traces = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        cases = args.keep or pathlib.Path(tmp)

        def kept(name: str, drawn: bool = False) -> pathlib.Path | None:
            return cases / name if drawn or args.keep else None
        for delay in args.delays:
            for scheme in args.schemes:
                rates = args.model_step_rates if scheme == 'model' else [None]
                for site_streams, rate in itertools.product(args.site_streams, rates):
                    drawn = bool(args.json and delay in FIGURE_DELAYS
                                 and site_streams == 'in-process' and rate == rates[0])
                    eased = '' if rate is None else f'-ease{rate:g}'
                    folder = kept(f'{scheme}-{delay:g}-{site_streams}{eased}', drawn)
                    rows.append(run(scheme, delay, jitter=args.jitter, loss=args.loss,
                                    domain_id=args.domain_id, site_streams=site_streams,
                                    keep=folder, model_step_rate=rate))
                    print_row(rows[-1])
                    if drawn:
                        traces[f'{scheme}, {1e3 * delay:g} ms one way, over ROS 2'] = read_scan(
                            folder / 'bag')
            if args.force_hold:
                rows.append(run('model', delay, jitter=args.jitter, loss=args.loss,
                                domain_id=args.domain_id, hold=HOLD_FORCE,
                                keep=kept(f'model-{delay:g}-held')))
                print_row(rows[-1])
        for trace in measured_traces(args.delay_trace, args.measured_link, cases):
            longest = float(DelayTrace.from_csv(trace).delays.max())
            for scheme in args.schemes:
                rows.append(run(scheme, longest, jitter=0.0, loss=args.loss,
                                domain_id=args.domain_id, delay_trace=trace,
                                keep=kept(f'{scheme}-{trace.stem}')))
                print_row(rows[-1])
            if 'model' in args.schemes:  # the baseline: bounds that do not follow the link
                rows.append(run('model', longest, jitter=0.0, loss=args.loss,
                                domain_id=args.domain_id, delay_trace=trace, fixed_bounds=True,
                                keep=kept(f'model-{trace.stem}-fixed')))
                print_row(rows[-1])
    print_hold_errors(rows)
    print('\nCPU, % of one core, over the press and the sweep (the machine has '
          f'{psutil.cpu_count()} cores):')
    names = list(rows[0]['cpu'])
    print(f'{"scheme":>6} {"ms":>6} {"streams":>10} ' + ' '.join(f'{n:>9}' for n in names)
          + f' {"total":>7}')
    for r in rows:
        print(f'{r["scheme"]:>6} {1e3 * r["delay"]:6.0f} {r["site_streams"]:>10} '
              + ' '.join(f'{r["cpu"][n]:9.1f}' for n in names)
              + f' {sum(r["cpu"].values()):7.1f}')
    result_files.write(args.json, rows)
    if traces:
        from report_generator.report_figures import teleop_figure

        teleop_figure(traces, FORCE_SCALE, args.json.with_suffix('.png'))
    return 0


if __name__ == '__main__':
    sys.exit(main())
