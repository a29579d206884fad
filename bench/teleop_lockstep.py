"""The telerobotic scan in lockstep, without ROS: the schemes' physics alone, reproducibly.

    .venv/bin/python bench/teleop_lockstep.py [--delays 0 0.01 0.025 0.05 0.1 0.25 0.5]
        [--jitter 0.2] [--loss 0.05] [--late] [--model-step-rates 5 0] [--force-hold]
        [--json PATH]

The same pieces as the ROS run, driven by one clock at 1 kHz: the simulated wand with its
scripted hand (the driver's ``SimulatedWand`` at 4 kHz, rendering the model locally or holding
the wrench), the leader, two ``EmulatedLink`` directions, the follower, the impedance robot on
the abdomen's Hunt–Crossley tissue (a flat skin at the phantom's front) and its F/T sensor.
What it shows is what the schemes do with a delay, free of a busy machine's timing; the ROS run
(``teleop_scan.py``) shows that the nodes do the same. Beside the launcher's three schemes it runs
``tdpa-plain``: TDPA's operator-side controller on the wand itself, without the virtual coupling
that ``tdpa`` puts between them, the baseline that chatters. With ``--late`` the operator's site
skips ticks as a busy machine makes it (the remote site keeps its own), and each case runs with
the driver's hold of the newest answer (as the launcher sets it) and without (the baseline).
``--model-step-rates`` runs ``model`` once per rate of the driver's easing of new models (N/s; 0:
each at once, the baseline; both by default, the fix beside what it replaces). With
``--force-hold`` each delay runs ``model`` once more with the remote site holding, through the
sweep, the force it measured as the sweep began; its force error beside the hand's own (the
patient's force about its mean over the same sweep, unheld).
"""
import argparse
import dataclasses
import itertools
import math
import sys

from bench import machine, result_files, teleop_scan
import numpy as np

from haptic_bringup.launcher import LATE_POSE_HOLD, LINK_TIMEOUT, MODEL_STEP_RATE, \
    SCAN_DURATION
from haptic_contract.contact_model import ContactModel, Kind, Plane
from haptic_contract.teleop import CommandLimits
from haptic_util.paths import package_file
from haptic_wand_driver.answer_deadline import AnswerDeadline
from haptic_wand_driver.assembly import local_renderer, port_passivity, simulated_wand_config
from haptic_wand_driver.params import WandDriverParams
from haptic_wand_driver.port_passivity import PortPassivity
from haptic_wand_driver.simulated import SimulatedWand
from link_emulator.link import EmulatedLink, LinkConfig, silence_timeout
from robot_site.assembly import follower as make_follower, ft_sensor, impedance_robot, tissue
from robot_site.params import FollowerParams, SimulatedRobotParams
from robot_site.tissue import PlaneSurface
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import WaypointScript
from teleop_leader.leader import Leader, LeaderConfig
from teleop_leader.params import LeaderParams

__all__ = ['as_series', 'hold_error', 'late_ticks', 'scan', 'ScanOptions', 'SCHEMES']

PLAIN_TDPA = 'tdpa-plain'  # TDPA's controller on the wand itself: the baseline of the coupling
SCHEMES = ('direct', PLAIN_TDPA, 'tdpa', 'model')

SCAN = 'package://teleop_leader/config/scan.yaml'
SKIN = -0.025  # [m] the phantom's front, under the probe's start
TICK = 1e-3  # [s]
MODEL_LIFETIME = LeaderParams().model_lifetime  # [s]
LATE_FRACTION, LATE_LONGEST = 0.02, 0.08  # of the ticks, late by up to [s]
SWEEP = teleop_scan.SWEEP
ZERO = np.zeros(3)


def _device(scheme: str, easing: float):
    """Build the driver's simulated wand and hand, rendering as the launcher sets ``scheme``."""
    wand = WandDriverParams()
    hand = OperatorHand(WaypointScript.from_file(package_file(SCAN)),
                        stiffness=wand.hand_stiffness, damping=wand.hand_damping)
    device = SimulatedWand(simulated_wand_config(wand), operator=hand)
    renderer = None
    if scheme == 'model':
        renderer = local_renderer(dataclasses.replace(wand, model_step_rate=easing),
                                  device.limits, port_passivity(wand))
        device.render_locally(renderer)
    return device, renderer


def _model(time: float, plane, tip) -> ContactModel:
    planes = () if plane is None else (Plane(
        tuple(plane.point), tuple(plane.normal), (plane.stiffness,) * 3, (plane.damping,) * 3,
        (0.0, 0.0, 0.0)),)
    return ContactModel(time, Kind.PLANES if planes else Kind.FREE, planes, math.inf,
                        MODEL_LIFETIME, math.inf, tuple(tip), (0.0,) * 6)


@dataclasses.dataclass(frozen=True)
class ScanOptions:
    """How one scan runs, beside its scheme and delay: the defaults are the launcher's (SI).

    ``jitter`` (s), ``loss`` and ``seed``: the link's, both ways. ``ticks``: the tick numbers at
    which the operator's site runs (a busy machine skips periods, as a ROS timer does), None for
    every one; the remote site runs every tick. ``hold``: the site's ``AnswerDeadline`` (the
    driver's ``hold_while_late``). ``easing``: the driver's ``model_step_rate`` (N/s; 0: each
    model at once, the baseline). ``link_timeout``: both ends' watchdogs (s); None waits out the
    jitter, as the launcher sets. ``force_hold``: (start, end) s, the remote site holding the
    force it measured at the start (``Follower.hold_force``) until the end. ``outage``: (start,
    end) s, the link carries nothing either way. ``answer_lag``: the driver takes each answer at
    its next tick, as from a leader in another process or over DDS (one site's process, handing
    its streams over in the process, answers at once).
    """

    jitter: float = 0.0
    loss: float = 0.0
    duration: float = SCAN_DURATION
    seed: int = 0
    ticks: np.ndarray | None = None
    hold: float = 0.0
    easing: float = MODEL_STEP_RATE
    link_timeout: float | None = None
    force_hold: tuple | None = None
    outage: tuple | None = None
    answer_lag: bool = False


def scan(scheme: str, delay: float, options: ScanOptions = ScanOptions()) -> dict:
    """Run the scan; return the operator's and the remote site's per-tick arrays.

    ``scheme`` is one of ``SCHEMES``: the launcher's, or ``tdpa-plain``. The site takes each
    answer as the driver does: held by ``AnswerDeadline(options.hold)``, a wrench through the
    device port's passivity controller unless the scheme is ``direct``. With
    ``options.force_hold`` the run has ``held`` (N).
    Returns ``time``, ``wand``, ``felt`` (applied since the tick before) at the operator's
    ticks, and ``remote_time``, ``patient``, ``tcp``.
    """
    timeout = (silence_timeout(LINK_TIMEOUT, options.jitter) if options.link_timeout is None
               else options.link_timeout)
    leader_config = (LeaderConfig('tdpa', coupling=None, link_timeout=timeout)
                     if scheme == PLAIN_TDPA else LeaderConfig(scheme, link_timeout=timeout))
    scheme = leader_config.scheme
    device, renderer = _device(scheme, options.easing)
    port = PortPassivity(WandDriverParams().passivity_max_damping if scheme == 'tdpa' else 0.0)
    answers = AnswerDeadline(options.hold)
    robot_params = SimulatedRobotParams()
    follower_params = dataclasses.replace(FollowerParams(), scheme=scheme, link_timeout=timeout)
    skin = PlaneSurface([0.0, 0.0, SKIN], [0.0, 0.0, 1.0])
    robot = impedance_robot(robot_params, tissue(robot_params, skin))
    sensor = ft_sensor(robot_params)
    robot_config = robot.config
    follower = make_follower(follower_params, CommandLimits(
        robot_config.workspace_lower, robot_config.workspace_upper,
        follower_params.max_command_speed), surface=lambda tcp: (skin.point, skin.normal))
    leader = Leader(leader_config, ZERO, robot_config.initial_position)
    link = LinkConfig(delay, options.jitter, options.loss, seed=options.seed)
    to_robot, to_operator = EmulatedLink(link), EmulatedLink(LinkConfig(
        delay, options.jitter, options.loss, seed=options.seed + 1))
    count = round(options.duration / TICK)
    cut = np.zeros(count + 1, dtype=bool)
    if options.outage is not None:
        cut[round(options.outage[0] / TICK):round(options.outage[1] / TICK)] = True
    operating = np.ones(count + 1, dtype=bool) if options.ticks is None else np.isin(
        np.arange(count + 1), options.ticks)
    operator_rows, remote_rows, held = [], [], np.nan
    wrench, last, pending = ZERO, 0.0, None
    state, remote = device.read(0.0), robot.read(0.0)
    for k in range(1, count):
        now = k * TICK
        if operating[k]:
            state = device.read(now)
            operator_rows.append((now, *state.position, *device.applied()[0]))
            shift = ZERO if renderer is None else renderer.planes_shift(
                (*state.position, state.roll, state.yaw))
            command = leader.command(now, state.position, state.linear_velocity, shift)
            if command is not None and not cut[k]:  # none until the feedback is heard
                to_robot.send(now, command)
        for delivery in to_robot.deliver(now):
            follower.receive(now, delivery.payload)
        if options.force_hold is not None and k == round(options.force_hold[0] / TICK):
            follower.hold_force(None)
            held = follower.hold.force
        elif options.force_hold is not None and k == round(options.force_hold[1] / TICK):
            follower.hold_force(0.0)
        reading = sensor.measure(now, remote.external_force).force
        robot.command(follower.target(now, remote.position, remote.velocity, reading, TICK))
        if not cut[k]:
            to_operator.send(now, follower.feedback(now))
        remote = robot.read(now + TICK)
        remote_rows.append((now + TICK, *remote.external_force, *remote.position))
        if not operating[k]:
            continue
        for delivery in to_operator.deliver(now):
            leader.receive(now, delivery.payload)
        if renderer is not None:
            known, plane = leader.model(now, state.position)
            answer = (now, _model(now, plane, state.position)) if known else None
        else:
            answer = (now, leader.force(now, state.position, state.linear_velocity,
                                        now - last))  # since its last pose, as the node has it
        last = now
        if options.answer_lag:
            answer, pending = pending, answer
        if answer is not None:  # taken as it comes, as in the site
            answers.taken(answer[0], MODEL_LIFETIME)
            if renderer is not None:
                renderer.take(answer[1], answers.deadline, now)
            else:
                wrench = port.control(answer[1], state.position, state.linear_velocity, TICK)
                device.apply(wrench, ZERO, until=answers.deadline)
        if answers.sent(now, now):  # out and not answered yet: what is held stops holding
            if renderer is not None:
                renderer.expire(answers.deadline)
            else:
                device.apply(wrench, ZERO, until=answers.deadline)
    operator, remote_table = np.array(operator_rows), np.array(remote_rows)
    return {'time': operator[:, 0], 'wand': operator[:, 1:4], 'felt': operator[:, 4:7],
            'remote_time': remote_table[:, 0], 'patient': remote_table[:, 1:4],
            'tcp': remote_table[:, 4:7], 'held': held}


def hold_error(run: dict, start: float, end: float) -> dict:
    """Return the patient's force against the held one (``teleop_scan.hold_error``).

    Without a hold (``held`` NaN), against the force's own mean over the same window: what the
    operator's hand keeps by itself.
    """
    return teleop_scan.hold_error(run['remote_time'], run['patient'], run['held'], start, end)


def late_ticks(duration: float, seed: int, *, late: float = LATE_FRACTION,
               longest: float = LATE_LONGEST) -> np.ndarray:
    """Tick numbers of a site on a busy machine: a fraction ``late`` of its ticks come late.

    A late tick skips 1 to ``longest`` s of periods, log-uniformly (a few long stalls among many
    short ones, as the driver's ticks under a CPU hog).
    """
    rng = np.random.default_rng(seed)
    gaps = np.where(rng.random(round(duration / TICK)) < late,
                    np.round(np.exp(rng.uniform(math.log(2.0 * TICK), math.log(longest),
                                                round(duration / TICK))) / TICK), 1)
    return np.cumsum(gaps.astype(np.int64))


def as_series(run: dict) -> dict:
    """Return the run as ``teleop_scan.read_scan`` gives a bag: topic → (times, vectors)."""
    return {'/wand/pose': (run['time'], run['wand']),
            '/wand/applied_wrench': (run['time'], run['felt']),
            '/remote/robot/ft_sensor/wrench': (run['remote_time'], run['patient']),
            '/remote/robot/tcp_pose': (run['remote_time'], run['tcp'])}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--schemes', nargs='+', default=list(SCHEMES), choices=SCHEMES)
    parser.add_argument('--delays', nargs='+', type=float,
                        default=[0.0, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5])
    parser.add_argument('--jitter', type=float, default=0.2, help='fraction of the delay')
    parser.add_argument('--loss', type=float, default=0.05)
    parser.add_argument('--late', action='store_true',
                        help=f"the operator's site ticks late ({100 * LATE_FRACTION:g} %% of its "
                        f'ticks, by up to {1e3 * LATE_LONGEST:g} ms): each case with the '
                        "driver's hold and without it (the baseline)")
    parser.add_argument('--model-step-rates', nargs='+', type=float,
                        default=[MODEL_STEP_RATE, 0.0],
                        help="model: the driver's easing of new models, N/s (0: at once)")
    parser.add_argument('--force-hold', action='store_true',
                        help='model once more per delay, the force held through the sweep')
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numpy")} (no ROS: one clock, lockstep)')
    teleop_scan.print_header()
    ticks = late_ticks(SCAN_DURATION, 0) if args.late else None
    rows = []
    for delay in args.delays:
        options = ScanOptions(jitter=args.jitter * delay, loss=args.loss, ticks=ticks)
        for scheme in args.schemes:
            rates = args.model_step_rates if scheme == 'model' else [MODEL_STEP_RATE]
            for hold, rate in itertools.product((LATE_POSE_HOLD, 0.0) if args.late else (0.0,),
                                                rates):
                run = scan(scheme, delay, dataclasses.replace(options, hold=hold, easing=rate))
                notes = ([f'late, hold {1e3 * hold:g} ms'] if args.late else []) + (
                    [f'ease {rate:g}'] if len(rates) > 1 else [])
                rows.append({'scheme': scheme, **teleop_scan.figures(as_series(run), delay),
                             'site_streams': ', '.join(notes), **hold_error(run, *SWEEP)})
                teleop_scan.print_row(rows[-1])
        if args.force_hold:
            run = scan('model', delay, dataclasses.replace(options, force_hold=SWEEP))
            rows.append({'scheme': 'model', **teleop_scan.figures(as_series(run), delay),
                         'site_streams': 'force held', **hold_error(run, *SWEEP)})
            teleop_scan.print_row(rows[-1])
    teleop_scan.print_hold_errors(rows)
    result_files.write(args.json, rows)
    return 0


if __name__ == '__main__':
    sys.exit(main())
