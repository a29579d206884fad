"""Round trip of the haptic loop over ROS 2: pose → collision → force → driver, per process layout.

    .venv/bin/python bench/bench_loop.py [--layouts separate composed] [--rates 1000]
                                         [--runs 3] [--duration 10]

Each run launches the real nodes (the simulated wand tapping the cuboid), lets the driver's
session run ``duration`` seconds at ``rate``, and reads the driver's own round-trip record: every
wrench carries the stamp of the pose it answers, so latency is measured on one clock. Printed per
run and pooled over runs: achieved pose rate (measured, not the timer setting), share of poses
answered, latency p50/p90/p99/max, and CPU of the loop's processes (100 % = one core).
"""
import argparse
import os
import pathlib
import sys
import tempfile
import time

import machine
import numpy as np
import psutil

from haptic_bringup.launcher import add_venv_prefix, Loop, LoopConfig

SCENE = 'package://collision_engine/scenes/cuboid.yaml'
CPU_WINDOW_SKIP = 1.0  # [s] CPU is measured inside the session, this far from either end


def cpu_seconds(pids) -> float:
    total = 0.0
    for pid in pids:
        times = psutil.Process(pid).cpu_times()
        total += times.user + times.system
    return total


def run_once(layout: str, rate: float, duration: float, domain_id: int) -> dict:
    """One session; returns the driver's loop record plus CPU [% of one core]."""
    with tempfile.TemporaryDirectory() as tmp:
        stats = pathlib.Path(tmp) / 'stats.npz'
        config = LoopConfig(
            composed=layout == 'composed', scene=SCENE, experiment='cuboid', duration=duration,
            domain_id=domain_id, run_dir=pathlib.Path(tmp) / 'launch',
            overrides={'wand_driver': {'rate': float(rate), 'stats_file': str(stats)},
                       'collision_engine': {'marker_rate': 0.0},
                       'force_renderer': {'marker_rate': 0.0}})
        with Loop(config) as loop:
            pids = list(loop.pids().values())
            # CPU over a window inside the session, while every process still runs.
            time.sleep(CPU_WINDOW_SKIP)
            cpu_start, wall_start = cpu_seconds(pids), time.monotonic()
            time.sleep(duration - 2 * CPU_WINDOW_SKIP)
            cpu = cpu_seconds(pids) - cpu_start
            wall = time.monotonic() - wall_start
            ended = loop.wait(duration + 10.0)
        if ended is None or not stats.exists():
            raise RuntimeError(f'{layout} at {rate} Hz: the session did not finish')
        record = dict(np.load(stats))
    record['cpu_percent'] = 100.0 * cpu / wall
    return record


def row(label: str, latencies: np.ndarray, record: dict) -> str:
    p50, p90, p99 = 1e3 * np.percentile(latencies, [50, 90, 99])
    return (f'{label:<28} {float(record["rate_hz"]):7.0f} {float(record["answered_percent"]):8.2f}'
            f' {p50:7.3f} {p90:7.3f} {p99:7.3f} {1e3 * latencies.max():7.2f}'
            f' {record["cpu_percent"]:6.0f}')


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--layouts', nargs='+', default=['separate', 'composed'],
                        choices=['separate', 'composed'])
    parser.add_argument('--rates', nargs='+', type=float, default=[1000.0])
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--duration', type=float, default=10.0)
    parser.add_argument('--domain-id', type=int, default=int(os.environ.get('ROS_DOMAIN_ID', 42)))
    args = parser.parse_args(argv)
    add_venv_prefix()
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    print(f'machine: {machine.line("rclpy", "numba")}')
    print(f'{args.runs} run(s) of {args.duration:g} s per layout and rate; latency in ms; '
          'CPU in % of one core, all loop processes')
    print(f'{"layout / rate / run":<28} {"pose Hz":>7} {"answered":>8} {"p50":>7} {"p90":>7} '
          f'{"p99":>7} {"max":>7} {"CPU %":>6}')
    for layout in args.layouts:
        for rate in args.rates:
            records = []
            for run in range(args.runs):
                record = run_once(layout, rate, args.duration, args.domain_id)
                records.append(record)
                print(row(f'{layout} {rate:g} Hz #{run + 1}', record['latencies'], record),
                      flush=True)
            pooled = {key: np.mean([float(r[key]) for r in records])
                      for key in ('rate_hz', 'answered_percent', 'cpu_percent')}
            latencies = np.concatenate([r['latencies'] for r in records])
            print(row(f'{layout} {rate:g} Hz, pooled', latencies, pooled), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
