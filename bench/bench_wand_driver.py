"""Per-call cost of the wand driver's device path, as the node's 1 kHz tick makes the calls.

    .venv/bin/python bench/bench_wand_driver.py [--repeats 5] [--seconds 10.5]

Timed, one call (or call group) at a time with ``time.perf_counter_ns`` after a warm-up:

- ``tick``: ``SimulatedWand.read(now)`` + ``WrenchCommand.current(now, yaw)`` + ``apply`` -- the
  node's timer callback without publishing. The wand is held by the operator hand running the
  paper's cuboid tapping script (exact box projection from ``ground_truth.wand``), and a
  160 N/m wall force on the cuboid is fed back every tick, so the wrench is fresh and the tip
  really taps.
- ``update``: ``WrenchCommand.update`` with the wall force as tuples of floats, as the node passes
  the message's fields.
- ``replay read``: ``ReplayDevice.read(now)`` on a looping 1 kHz CSV recording of the script.

Each repeat builds everything anew and runs ``seconds`` of 1 kHz ticks; printed per repeat are
the median and p99 in µs, then the spread over repeats (min..max of each). The timer's own cost
(an empty timed region) is printed apart: it is included in every figure.
"""

import argparse
from pathlib import Path
import sys
import tempfile
import time

from bench import machine
from ground_truth.wand import Box, wall_force
import numpy as np

from haptic_wand_driver.replay import ReplayDevice
from haptic_wand_driver.simulated import SimulatedWand
from haptic_wand_driver.wrench_input import WrenchCommand
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import cuboid_face_tapping

__all__ = ['run_repeat', 'main']

TICK = 1e-3  # [s] the node's timer period
WARM_UP = 500  # ticks left out of the statistics at the start of each repeat
CUBOID = Box([0.0, 0.0, -0.075], [0.2, 0.1, 0.1])
WRENCH_TIMEOUT = 0.010  # [s] the node's default


def _timer_cost(calls: int) -> np.ndarray:
    """Nanoseconds of an empty timed region."""
    clock = time.perf_counter_ns
    samples = np.empty(calls, dtype=np.int64)
    for index in range(calls):
        start = clock()
        samples[index] = clock() - start
    return samples


def _write_recording(path: Path, seconds: float) -> None:
    """Write a 1 kHz pose CSV of the cuboid script's targets, for the replay device."""
    script = cuboid_face_tapping(CUBOID.project)
    times = np.arange(0.0, seconds, TICK)
    rows = np.column_stack([times, [script.target(t).coordinates for t in times]])
    np.savetxt(path, rows, delimiter=',', header='t,x,y,z,roll,yaw', comments='')


def run_repeat(seconds: float, recording: Path) -> dict[str, np.ndarray]:
    """One repeat: per-call nanoseconds of tick, update and replay read, after the warm-up."""
    clock = time.perf_counter_ns
    wand = SimulatedWand(operator=OperatorHand(cuboid_face_tapping(CUBOID.project)))
    limits = wand.limits
    wrench = WrenchCommand(force_limit=limits.force_limit, torque_limit=limits.torque_limit,
                           timeout=WRENCH_TIMEOUT)
    replay = ReplayDevice(recording, loop=True)
    no_torque = (0.0, 0.0, 0.0)
    times = np.arange(0.0, seconds, TICK).tolist()
    samples = {name: np.empty(len(times), dtype=np.int64)
               for name in ('tick', 'update', 'replay read')}
    for index, now in enumerate(times):
        start = clock()
        state = wand.read(now)
        wand.apply(*wrench.current(now, state.yaw))
        samples['tick'][index] = clock() - start
        force = tuple(wall_force(CUBOID, state.position, state.linear_velocity).tolist())
        start = clock()
        wrench.update(force, no_torque, now, now)
        samples['update'][index] = clock() - start
        start = clock()
        replay.read(now)
        samples['replay read'][index] = clock() - start
    return {name: values[WARM_UP:] for name, values in samples.items()}


def _summary(nanoseconds: np.ndarray) -> tuple[float, float]:
    """Median and p99, µs."""
    median, p99 = np.percentile(nanoseconds, [50, 99]) * 1e-3
    return float(median), float(p99)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeats', type=int, default=5)
    parser.add_argument('--seconds', type=float, default=10.5,
                        help='simulated seconds (1 kHz ticks) per repeat')
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numpy", "numba")}')
    timer_median, timer_p99 = _summary(_timer_cost(100_000))
    print(f'timer cost (included below): median {timer_median:.3f} µs, p99 {timer_p99:.3f} µs')
    print(f'{args.repeats} repeat(s) of {args.seconds:g} s at 1 kHz, {WARM_UP} warm-up ticks '
          'dropped each; µs per call')
    print(f'{"call":<12} {"repeat":>6} {"calls":>6} {"median":>8} {"p99":>8}')
    figures: dict[str, list[tuple[float, float]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        recording = Path(tmp) / 'cuboid_targets.csv'
        _write_recording(recording, args.seconds)
        for repeat in range(args.repeats):
            for name, nanoseconds in run_repeat(args.seconds, recording).items():
                median, p99 = _summary(nanoseconds)
                figures.setdefault(name, []).append((median, p99))
                print(f'{name:<12} {repeat + 1:>6} {len(nanoseconds):>6} {median:8.2f} '
                      f'{p99:8.2f}', flush=True)
    print('spread over repeats (min..max), µs per call:')
    for name, rows in figures.items():
        medians, p99s = np.array(rows).T
        print(f'{name:<12} median {medians.min():7.2f}..{medians.max():<7.2f} '
              f'p99 {p99s.min():7.2f}..{p99s.max():.2f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
