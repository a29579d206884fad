"""The main job: the simulated wand taps the paper's objects over ROS 2, recorded and summarised.

    demo [--experiments cuboid cylinder hand cuboid-no-force probe-flat probe-phantom teleop]
         [--separate] [--out build/demo]

For each experiment it launches the loop (driver, collision engine and force renderer in one
process, as ``haptic_loop`` does; in three with ``--separate``) and a recorder, lets the scripted
operator tap for 10 s, stops, reads the bag back and prints one line per contact: depth, mean force
per axis, and how far the force pointed from the normal.
``cuboid-no-force`` is the control: the same taps with the force held at zero, to show how deep
the operator's hand would go if nothing pushed back. ``probe-flat`` and ``probe-phantom`` sweep
a linear probe (a 10 x 40 mm face) rolled and yawed +-20 degrees on a flat slab and on the
patient phantom: force and torque about the tip. ``teleop`` is the telerobotic scan: the
operator's site and the remote robot on the patient phantom, in two DDS domains, model-mediated
over a 50 ms link (5 ms jitter, 1 % loss), the remote site imaging the probe's view; it prints
the force the patient felt and the hand felt, the round trip the operator measured, and the
probe's frames the operator received.
"""
import argparse
import os
import pathlib
import shutil
import sys
import time

import numpy as np

from haptic_bringup.bag import typestore_with
from haptic_bringup.contacts import contact_intervals, format_contacts
from haptic_bringup.launcher import add_venv_prefix, Loop, LoopConfig, SCAN_DURATION
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import (published_counts, PUBLISHERS, read_frames, read_session,
                                    read_vectors, reported, topic_counts)
from haptic_contract.graph import absolute, REMOTE_PREFIX, ROBOT_FT_WRENCH, WAND_APPLIED_WRENCH
from haptic_contract.teleop import Scheme

__all__ = ['main', 'EXPERIMENTS', 'run_experiment']

# name → (scene, operator script, parameter overrides)
EXPERIMENTS = {
    'cuboid': ('package://collision_engine/scenes/cuboid.yaml', 'cuboid', {}),
    'cylinder': ('package://collision_engine/scenes/cylinder.yaml', 'cylinder', {}),
    'hand': ('package://collision_engine/scenes/hand.yaml', 'hand', {}),
    'cuboid-no-force': ('package://collision_engine/scenes/cuboid.yaml', 'cuboid',
                        {'force_renderer': {'force_limit': 0.0}}),
    'probe-flat': ('package://collision_engine/scenes/probe_flat.yaml', 'probe', {}),
    'probe-phantom': ('package://collision_engine/scenes/probe_phantom.yaml', 'probe', {}),
}
DURATION = 10.0  # [s] as the paper's experiments
TELEOP = 'teleop'
TELEOP_LINK = {'delay': 0.05, 'jitter': 0.005, 'loss': 0.01}  # [s, s, probability]
TELEOP_SCHEME = Scheme.MODEL.value
FORCE_SCALE = 0.3  # the leader's default


def run_experiment(name: str, out: pathlib.Path, *, composed: bool = True,
                   duration: float = DURATION, domain_id: int = 42) -> dict:
    """Run one experiment over ROS 2 and return where its bag and loop statistics are."""
    run = out / name
    shutil.rmtree(run, ignore_errors=True)
    run.mkdir(parents=True)
    stats = run / 'loop_stats.npz'
    scene, script, overrides = EXPERIMENTS[name]
    config = LoopConfig(composed=composed, scene=scene, experiment=script, duration=duration,
                        record=str(run / 'bag'), domain_id=domain_id, run_dir=run / 'launch',
                        overrides={**overrides, 'wand_driver': {'stats_file': str(stats)}})
    with Loop(config) as loop:
        ended = loop.wait(duration + 10.0)
        if ended is None or ended.name not in ('wand_driver', 'composed'):
            raise RuntimeError(f'{name}: the driver did not end its experiment '
                               f'({ended.name if ended else "timeout"})')
    return {'bag': run / 'bag', 'stats': stats}


def run_teleop(out: pathlib.Path, *, domain_id: int = 42) -> pathlib.Path:
    """Run the telerobotic scan over ROS 2 (two domains, the site gateways); return its bag."""
    run = out / TELEOP
    shutil.rmtree(run, ignore_errors=True)
    run.mkdir(parents=True)
    config = LoopConfig(teleop=TELEOP_SCHEME, link=dict(TELEOP_LINK), record=str(run / 'bag'),
                        domain_id=domain_id, run_dir=run / 'launch', imaging=True)
    with Loop(config) as loop:
        ended = loop.wait(SCAN_DURATION + 30.0)
        if ended is None or ended.name != 'operator':
            raise RuntimeError(f'{TELEOP}: the operator did not end the scan '
                               f'({ended.name if ended else "timeout"})')
    return run / 'bag'


def summarise_teleop(bag: pathlib.Path) -> str:
    """Summarise the scan: the patient's force and the hand's while pressing, the round trip."""
    typestore = typestore_with(custom_definitions())
    felt_topic = absolute(WAND_APPLIED_WRENCH)
    patient_topic = REMOTE_PREFIX + absolute(ROBOT_FT_WRENCH)
    series = read_vectors(bag, typestore, {felt_topic: 'wrench', patient_topic: 'wrench'})
    patient = np.linalg.norm(series[patient_topic][1], axis=1)
    felt = np.linalg.norm(series[felt_topic][1], axis=1)
    round_trip = reported(bag, typestore, 'round_trip_s').get('teleop_leader', ['nan'])[-1]
    frames = read_frames(bag, typestore)
    latency = frames.received - frames.stamp
    late = 1e3 * np.percentile(latency, (50, 99)) if len(latency) else (np.nan, np.nan)
    return (f'== {TELEOP}: {TELEOP_SCHEME} over a {1e3 * TELEOP_LINK["delay"]:g} ms link ==\n'
            f'patient force: median {np.median(patient[patient > 1.0]):.2f} N in contact, peak '
            f'{patient.max():.2f} N; felt / {FORCE_SCALE:g}: median '
            f'{np.median(felt[felt > FORCE_SCALE]) / FORCE_SCALE:.2f} N; round trip measured by '
            f'the operator from echoed stamps: {1e3 * float(round_trip):.1f}'
            f' ms\nprobe image: {len(frames.stamp)} frames at the operator; pose to image p50 '
            f'{late[0]:.0f} ms, p99 {late[1]:.0f} ms')


def summarise(name: str, files: dict) -> str:
    """Summarise one experiment: its contacts and the loop's figures, as text."""
    typestore = typestore_with(custom_definitions())
    session = read_session(files['bag'], typestore)
    contacts = contact_intervals(session)
    loop = np.load(files['stats'])
    recorded = topic_counts(files['bag'])
    published = published_counts(files['bag'], typestore)
    lines = [
        f'== {name}: {len(contacts)} contacts in {session.time[-1]:.1f} s, deepest '
        f'{1e3 * max((c.max_depth for c in contacts), default=0.0):.2f} mm ==',
        format_contacts(contacts),
        f'loop: {float(loop["rate_hz"]):.0f} Hz, {float(loop["answered_percent"]):.1f} % of '
        f'{int(loop["poses"])} poses answered, round trip p50 '
        f'{1e3 * float(loop["latency_p50_s"]):.2f} ms, p99 '
        f'{1e3 * float(loop["latency_p99_s"]):.2f} ms',
        'published / recorded: ' + ', '.join(
            f'{topic} {published.get(topic, "?")}/{recorded.get(topic, 0)}'
            for topic in sorted(published.keys() | (recorded.keys() & PUBLISHERS.keys()))),
    ]
    return '\n'.join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog='demo', description=__doc__.split('\n\n')[0])
    parser.add_argument('--experiments', nargs='+', choices=[*EXPERIMENTS, TELEOP],
                        default=[*EXPERIMENTS, TELEOP])
    parser.add_argument('--separate', action='store_true',
                        help='three processes for the loop (default: one, as haptic_loop)')
    parser.add_argument('--out', default='build/demo', type=pathlib.Path)
    parser.add_argument('--domain-id', type=int,
                        default=int(os.environ.get('ROS_DOMAIN_ID', 42)))
    args = parser.parse_args(argv)
    add_venv_prefix()
    started = time.monotonic()
    for count, name in enumerate(args.experiments, 1):
        step = time.monotonic()
        print(f'[demo] {count}/{len(args.experiments)} {name}: {_what(name)} ...', flush=True)
        try:
            print(_run_and_summarise(name, args), flush=True)
        except RuntimeError as error:
            print(f'[demo] {error}', file=sys.stderr)
            return 1
        print(f'[demo]     {name}: done in {time.monotonic() - step:.0f} s', flush=True)
    print(f'[demo] done in {time.monotonic() - started:.0f} s; bags in {args.out}')
    return 0


def _what(name: str) -> str:
    if name == TELEOP:
        return f'scanning the patient phantom through the remote robot for {SCAN_DURATION:g} s'
    return f'tapping for {DURATION:g} s over ROS 2'


def _run_and_summarise(name: str, args) -> str:
    if name == TELEOP:
        return summarise_teleop(run_teleop(args.out, domain_id=args.domain_id))
    return summarise(name, run_experiment(name, args.out, composed=not args.separate,
                                          domain_id=args.domain_id))


if __name__ == '__main__':
    raise SystemExit(main())
