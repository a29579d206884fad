"""The telerobotic scan quiet and with cores hogged: the fix beside the code before it.

    .venv/bin/python bench/teleop_load.py [--schemes model tdpa] [--loads quiet hogged busy]
        [--rounds 1] [--baseline d242b42] [--duration 20] [--json PATH] [--keep DIR]

Each case is the issue's command as a user types it, ``haptic_loop --teleop SCHEME --delay 0.1
--jitter 0.01 --loss 0.01 --duration 20 --record DIR``: run from this tree (the fix) and from
the code at ``--baseline`` (``git archive`` of it, run with this venv), alternated in one run,
scheme by scheme and load by load: on a quiet machine (``quiet``), with another process keeping
one of the two cores busy (``hogged``), and with two keeping both busy (``busy``: what the issue
saw, the driver at 763 Hz on a busy machine, takes more than one hog here when nothing else
runs). Every figure is ``teleop_scan.figures`` of the bag, from what the device applied to
the hand and where the wand was (measured from outside, not from the controllers' books): net
work on the hand and oscillation (stable: <= 0 and <= 10 %; a session in contact with the
patient for less than 5 s, which a starved remote site can make, says neither), transparency,
the patient's peak force. Beside them: the rate the wand published at, how many of its poses
came more than 10 ms after the one before (the ticks that outlived an answer's lifetime) and
the longest gap, the remote site's rate, the link's silences (feedback more than 0.1 s apart:
the leader renders nothing then, and starts again where the wand is), the load average when the
case started (other work shares the machine) and the session's exit code.
"""
import argparse
import functools
import os
import pathlib
import subprocess
import sys
import tempfile
import time

from bench import machine, result_files, ros_domain, teleop_scan
import numpy as np
from rosbags.highlevel import AnyReader

from haptic_bringup.bag import typestore_with
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import read_vectors

__all__ = ['case', 'main', 'verdict']

REPOSITORY = pathlib.Path(__file__).resolve().parents[1]
# The code before the fix (main before 'passive' was merged), which shares this tree's messages:
# the 0139399 does not (the safety issue added fields), so it cannot run with this venv.
BASELINE = 'd242b42'
DELAY, JITTER, LOSS, DURATION = 0.1, 0.01, 0.01, 20.0  # the command
LATE = 0.010  # [s] between two poses: longer than an answer's lifetime
MIN_CONTACT = 5.0  # [s] in contact: the scan presses for about 12 s
SILENT = 0.1  # [s] between two feedbacks: the leader's link_timeout, it renders nothing
HOG = 'while True: pass'
LOADS = {'quiet': 0, 'hogged': 1, 'busy': 2}  # processes keeping a core busy
WARM = ('from collision_engine import load_scene; from haptic_util.paths import package_file; '
        'from haptic_wand_driver import servo_loop; servo_loop.compile_now(); '
        "load_scene(package_file('package://collision_engine/scenes/phantom.yaml'))")


def baseline_tree(ref: str, into: pathlib.Path) -> dict:
    """Unpack the packages at ``ref`` into ``into``; return the environment that runs them.

    Its Python packages (the messages are this venv's) come first on the path; their share
    folders (parameters, scenes) are found through an ament prefix of their own, ahead of the
    venv's: a package since renamed (``remote_probe``) has none in the venv.
    """
    archive = subprocess.run(['git', '-C', str(REPOSITORY), 'archive', ref, 'src'],
                             check=True, capture_output=True).stdout
    subprocess.run(['tar', '-x', '-C', str(into)], input=archive, check=True)
    packages = sorted(folder.name for folder in (into / 'src').iterdir()
                      if (folder / folder.name / '__init__.py').exists())
    prefix = into / 'install'
    index = prefix / 'share' / 'ament_index' / 'resource_index' / 'packages'
    index.mkdir(parents=True)
    for package in packages:
        (index / package).touch()
        (prefix / 'share' / package).symlink_to(into / 'src' / package)
    paths = [str(into / 'src' / package) for package in packages]
    env = {**os.environ,
           'PYTHONPATH': os.pathsep.join([*paths, *filter(None, [os.environ.get('PYTHONPATH')])]),
           'AMENT_PREFIX_PATH': os.pathsep.join(
               [str(prefix), *filter(None, [os.environ.get('AMENT_PREFIX_PATH')])])}
    subprocess.run([sys.executable, '-c', WARM], env=env, check=True)  # numba's caches there
    return env


def case(scheme: str, folder: pathlib.Path, env: dict, domain_id: int,
         duration: float = DURATION) -> dict:
    """Run the issue's command once into ``folder``; return the bag's figures."""
    command = [str(pathlib.Path(sys.executable).with_name('haptic_loop')), '--teleop', scheme,
               '--delay', str(DELAY), '--jitter', str(JITTER), '--loss', str(LOSS),
               '--duration', str(duration), '--record', str(folder / 'bag'),
               '--domain-id', str(domain_id), '--run-dir', str(folder / 'launch')]
    load = os.getloadavg()[0]
    done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=240)
    if not (folder / 'bag').exists():  # a session that stopped badly still leaves its bag
        raise RuntimeError(f'{" ".join(command)} exited {done.returncode}, no bag:\n'
                           f'{done.stderr[-2000:]}')
    stamps = read_vectors(folder / 'bag', typestore_with(custom_definitions()),
                          {'/wand/pose': 'pose'}, stamped=True)['/wand/pose'][0]
    gaps = np.diff(stamps)
    scan = teleop_scan.read_scan(folder / 'bag')
    return {**teleop_scan.figures(scan, DELAY), 'rate_hz': _rate(stamps),
            'remote_rate_hz': _rate(scan['/remote/robot/tcp_pose'][0]),
            'silences': _silences(folder / 'bag'),
            'late_poses': int(np.sum(gaps > LATE)), 'longest_gap_s': float(gaps.max()),
            'load_before': load, 'exit_code': done.returncode}


def _rate(times: np.ndarray) -> float:
    return float(len(times) / (times[-1] - times[0]))


def _silences(bag: pathlib.Path) -> int:
    """Count the feedback's gaps longer than the leader's link timeout, as the recorder got it."""
    parts = sorted(metadata.parent for metadata in bag.glob('**/metadata.yaml'))  # a site's each
    with AnyReader(parts, default_typestore=typestore_with(custom_definitions())) as reader:
        feedback = [c for c in reader.connections if c.topic == '/teleop/feedback']
        times = np.array([stamp for _, stamp, _ in reader.messages(connections=feedback)])
    return int(np.sum(np.diff(times * 1e-9) > SILENT))


def loaded(run, hogs: int):
    """Run ``run()`` with ``hogs`` other processes each keeping a core busy."""
    load = [subprocess.Popen([sys.executable, '-c', HOG]) for _ in range(hogs)]
    try:
        time.sleep(1.0)  # let them take their cores
        return run()
    finally:
        for hog in load:
            hog.kill()
            hog.wait()


def verdict(row: dict) -> str:
    """Stable or not; a session that never pressed the patient says nothing either way."""
    if row['contact_s'] < MIN_CONTACT:
        return 'no touch'
    return 'yes' if row['stable'] else 'NO'


def print_row(row: dict) -> None:
    print(f'{row["scheme"]:>6} {row["load"]:>7} {row["code"]:>9} {row["rate_hz"]:6.0f} '
          f'{row["late_poses"]:5d} {1e3 * row["longest_gap_s"]:6.1f} '
          f'{row["remote_rate_hz"]:6.0f} {row["silences"]:4d} '
          f'{verdict(row):>6} {row["contact_s"]:5.1f} {1e3 * row["net_work_j"]:8.1f} '
          f'{row["oscillation_percent"]:6.1f} {row["transparency_percent"]:6.1f} '
          f'{row["peak_patient_n"]:6.2f} {row["load_before"]:7.1f} {row["exit_code"]:4d}',
          flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--schemes', nargs='+', default=['model', 'tdpa'],
                        choices=['direct', 'tdpa', 'model'])
    parser.add_argument('--loads', nargs='+', default=list(LOADS), choices=list(LOADS))
    parser.add_argument('--rounds', type=int, default=1)
    parser.add_argument('--baseline', default=BASELINE, help='git ref of the code before')
    ros_domain.add_option(parser)
    parser.add_argument('--duration', type=float, default=DURATION,
                        help="the session's length, s (the issue's: 20)")
    result_files.add_option(parser)
    parser.add_argument('--keep', type=pathlib.Path, help='keep each case\'s bag under here')
    args = parser.parse_args(argv)
    ros_domain.keep_local()
    started = machine.line('ros-jazzy-rclpy')
    print(f'machine: {started}; load average {os.getloadavg()[0]:.1f} at the start')
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        cases = args.keep or tmp
        (tmp / 'baseline').mkdir()
        codes = {'fix': dict(os.environ), args.baseline: baseline_tree(args.baseline,
                                                                       tmp / 'baseline')}
        print(f'{"scheme":>6} {"load":>7} {"code":>9} {"Hz":>6} {">10ms":>5} {"gap ms":>6} '
              f'{"rem Hz":>6} {"sil":>4} '
              f'{"stable":>6} {"touch":>5} {"work mJ":>8} {"osc %":>6} {"err %":>6} '
              f'{"peak N":>6} '
              f'{"loadavg":>7} {"exit":>4}')
        for _ in range(args.rounds):
            for scheme in args.schemes:
                for load in args.loads:
                    for code, env in codes.items():
                        folder = cases / f'{len(rows)}-{scheme}-{load}-{code}'
                        folder.mkdir(parents=True)
                        run = functools.partial(case, scheme, folder, env, args.domain_id,
                                                args.duration)
                        row = {'scheme': scheme, 'load': load, 'code': code,
                               **loaded(run, LOADS[load])}
                        rows.append(row)
                        print_row(row)
                        # After each case: a run cut short keeps what it measured.
                        result_files.write(args.json, {'baseline': args.baseline, 'rows': rows})
    return 0


if __name__ == '__main__':
    sys.exit(main())
