"""What each node published against what the bag holds, quiet and with cores kept busy.

    .venv/bin/python bench/recording_load.py [--layouts composed separate teleop composed-rp]
        [--stops end launcher all] [--hogs 0 1] [--runs 1] [--seconds 6]

Each run records a session (``haptic_bringup.launcher.Loop``, as ``haptic_loop --record``
does) and ends it one of three ways: ``end``, its own end (``--duration``); ``launcher``, a
Ctrl-C to the local launcher, which stops its processes in order; ``all``, a Ctrl-C as ``ros2
launch`` passes it on: SIGINT to every process of the session at once, twice, 2 ms apart. The
layouts: ``composed``, the loop's process records itself (``haptic_loop``'s default);
``separate``, three processes and a recorder process; ``teleop``, the model-mediated scan over a
50 ms link, each site's process recording itself; ``composed-rp``, the composed loop with a
recorder process instead (the layout before the recorder moved in, the baseline). ``--hogs`` is
how many processes spin on a core each meanwhile (the machine has two); hogged and quiet runs
alternate.

Published counts are what each node says in its final ``/diagnostics`` report; recorded, what
the bag holds (the site's bag for a telerobotic site's own streams). Per run: the totals, every
topic that lost any, what the recorders said they dropped (a full queue) and lost (DDS, a
recorder process), the CPU of all the session's processes per pose over the middle third of
a run that ends by itself (its recorder's included, wherever it runs) with the driver's tick
period over it (p50, p99, max, from the poses' stamps), and the load average.
"""
import argparse
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

from bench import machine, ros_domain
import numpy as np
import psutil

from haptic_bringup.bag import typestore_with
from haptic_bringup.launcher import Loop, LoopConfig
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import (published_counts, PUBLISHERS, read_vectors, reported,
                                    SITE_PUBLISHERS, topic_counts)

LAYOUTS = ('composed', 'separate', 'teleop', 'composed-rp')
STOPS = ('end', 'launcher', 'all')
SCENE = 'package://collision_engine/scenes/cuboid.yaml'
TELEOP_LINK = {'delay': 0.05, 'jitter': 0.005, 'loss': 0.01}
GAP = 0.002  # [s] between the two SIGINTs of ``all``
HOG = 'while True: pass'


def config(layout: str, seconds: float, folder: pathlib.Path, domain_id: int) -> LoopConfig:
    common = {'duration': seconds, 'record': str(folder / 'bag'), 'domain_id': domain_id,
              'run_dir': folder / 'launch'}
    if layout == 'teleop':
        return LoopConfig(teleop='model', link=dict(TELEOP_LINK), **common)
    return LoopConfig(scene=SCENE, experiment='cuboid', composed=layout != 'separate',
                      record_in_process=layout != 'composed-rp', **common)


def run(layout: str, stop: str, hogs: int, seconds: float, domain_id: int) -> dict:
    """One recorded session; what was published and recorded per topic, and what dropped."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        load = [subprocess.Popen([sys.executable, '-S', '-c', HOG]) for _ in range(hogs)]
        try:
            with Loop(config(layout, seconds, folder, domain_id)) as loop:
                if stop == 'end':
                    window = cpu_window(loop, seconds)
                    loop.wait(seconds + 60.0)
                else:
                    time.sleep(seconds / 2)
                    if stop == 'all':
                        interrupt_all(loop)
        finally:
            for hog in load:
                hog.kill()
                hog.wait()
        typestore = typestore_with(custom_definitions())
        publishers = SITE_PUBLISHERS if layout == 'teleop' else PUBLISHERS
        published = published_counts(folder / 'bag', typestore, publishers)
        recorded = topic_counts(folder / 'bag')
        said = {key: {name: int(values[-1]) for name, values
                      in reported(folder / 'bag', typestore, key).items()}
                for key in ('dropped', 'lost')}
        if stop == 'end':
            start, end, cpu = window
            received = read_vectors(folder / 'bag', typestore, {'/wand/pose': 'pose'})
            inside = (received['/wand/pose'][0] >= start) & (received['/wand/pose'][0] < end)
            said['cpu_per_pose'] = cpu / np.count_nonzero(inside)
            ticks = np.diff(read_vectors(folder / 'bag', typestore, {'/wand/pose': 'pose'},
                                         stamped=True)['/wand/pose'][0][inside])
            said['ticks'] = np.percentile(ticks, [50, 99]).tolist() + [float(ticks.max())]
    return {'published': published, 'unreported': sorted(set(publishers) - set(published)),
            'recorded': {topic: recorded.get(topic, 0) for topic in publishers}, **said,
            'load': os.getloadavg()[0]}


def cpu_window(loop: Loop, seconds: float) -> tuple:
    """CPU of every process of the session over its middle third: (start s, end s, CPU s)."""
    processes = [psutil.Process(child.pid) for child in loop.children]
    time.sleep(seconds / 3)
    before, start = sum(_cpu(p) for p in processes), time.time()
    time.sleep(seconds / 3)
    return start, time.time(), sum(_cpu(p) for p in processes) - before


def _cpu(process: psutil.Process) -> float:
    times = process.cpu_times()
    return times.user + times.system


def interrupt_all(loop: Loop) -> None:
    """Ctrl-C as ``ros2 launch`` passes it on: every process at once, twice; wait for them."""
    for _ in range(2):
        for child in loop.children:
            child.signal(signal.SIGINT)
        time.sleep(GAP)
    for child in loop.children:
        child.process.wait(60.0)


def line(layout: str, stop: str, hogs: int, result: dict) -> str:
    published, recorded = result['published'], result['recorded']
    lost = {topic: published[topic] - recorded[topic] for topic in published
            if published[topic] != recorded[topic]}
    return (f'{layout:<12} {stop:<9} {hogs:>4} {sum(published.values()):>10} '
            f'{sum(recorded[t] for t in published):>10}  lost {lost or "none"}'
            + (f'  no final report: {result["unreported"]}' if result['unreported'] else '')
            + f'  recorders: dropped {result["dropped"]}, lost {result["lost"]}'
            + (f'  CPU {1e6 * result["cpu_per_pose"]:.0f} us a pose, tick p50/p99/max '
               + '/'.join(f'{1e3 * t:.2f}' for t in result['ticks']) + ' ms'
               if 'cpu_per_pose' in result else '')
            + f'  load {result["load"]:.1f}')


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--layouts', nargs='+', default=list(LAYOUTS), choices=LAYOUTS)
    parser.add_argument('--stops', nargs='+', default=list(STOPS), choices=STOPS)
    parser.add_argument('--hogs', nargs='+', type=int, default=[0, 1])
    parser.add_argument('--runs', type=int, default=1)
    parser.add_argument('--seconds', type=float, default=6.0)
    ros_domain.add_option(parser)
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    print(f'machine: {machine.line("ros-jazzy-rclpy")}')
    print(f'{"layout":<12} {"stop":<9} {"hogs":>4} {"published":>10} {"recorded":>10}')
    for _ in range(args.runs):
        for layout in args.layouts:
            for stop in args.stops:
                for hogs in args.hogs:
                    result = run(layout, stop, hogs, args.seconds, args.domain_id)
                    print(line(layout, stop, hogs, result), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
