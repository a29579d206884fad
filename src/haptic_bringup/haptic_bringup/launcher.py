"""The local launcher: the haptic loop without ros2cli or launch (PyPI installs).

    haptic_loop [--separate] [--scene SCENE] [--experiment NAME] [--duration S] [--record DIR]
    haptic_loop --teleop SCHEME [--delay S] [--jitter S] [--loss P] [--record DIR]

starts the wand driver, the collision engine and the force renderer in one process on one
executor, their 1 kHz streams handed over in the process (``haptic_bringup.composed``): on two
cores, the layout that holds the loop's CPU budget with a recorder and an outside client, as
Nav2's bring-up composes its nodes by default. ``--separate`` starts them as three processes, as
``ros2 run`` would: to watch one node's CPU, or to run one elsewhere, at a cost in CPU that
``docs/cpu_budget.md`` gives. It sets local-only DDS discovery, a domain id, and ROS logs under
``build/``. It waits for the loop's topics to be discovered, runs until the driver's experiment
ends, ``--duration`` passes or Ctrl-C, then stops every process and removes stale shared memory.
``--record DIR`` records the loop to the bag DIR from inside its process
(``haptic_bringup.process_recorder``: nothing is lost, however busy the machine); with
``--separate``, a recorder process does (``haptic_bringup.recorder``), stopped last. On a full
ROS 2 install, ``ros2 launch haptic_bringup haptic_loop.launch.py`` does the same.

With ``--teleop direct|tdpa|model`` it runs a telerobotic session instead: the operator's site (the
wand driver and the leader, one process) in one DDS domain, the remote site (the robot with its F/T
sensor on the patient phantom and the follower, one process; with ``--imaging``, the probe's
imager, a process of its own) in the next domain, and both sites' gateways between them
(``haptic_bringup.site.loopback_gateways``): the deployed path, over loopback mutual TLS, each
gateway delaying, jittering and dropping what it sends. With ``--record DIR`` each site's process
records itself: DIR is the session, holding the bags ``operator`` and ``remote`` (the remote one's
topics under ``/remote/``).
"""
import argparse
import dataclasses
import itertools
import math
import os
import pathlib
import sys
import time
from typing import Optional

from ament_index_python.packages import get_package_share_directory
import yaml

from haptic_bringup.discovery import GraphWatcher
from haptic_bringup.processes import (clean_stale_shm, run_until_stopped, start_child,
                                      stop_children, wait_any_exit)
from haptic_contract.graph import (absolute, COLLISION_STATE, DIAGNOSTICS, GATEWAY, IMAGER,
                                   LOOP_RECORDER,
                                   NODES, OPERATOR_RECORDED, OPERATOR_RECORDER, OPERATOR_SITE,
                                   PROBE_IMAGE, RECORDERS, REMOTE_PREFIX, REMOTE_RECORDED,
                                   REMOTE_RECORDER, REMOTE_SITE, ROBOT_FT_WRENCH,
                                   ROBOT_TARGET_POSE, ROBOT_TCP_POSE, TELEOP_COMMAND,
                                   TELEOP_FEEDBACK, TELEOP_NODES, WAND_CONTACT_MODEL, WAND_POSE,
                                   WAND_WRENCH)
from haptic_contract.teleop import Scheme, SCHEMES
from haptic_util import shared_memory
from haptic_util.executor import end_process
from haptic_util.transport import deep_shared_memory_environment
from link_emulator.link import delay_spread, DelayTrace, silence_timeout
from teleop_protocol.admission import AdmissionConfig

__all__ = ['LoopConfig', 'Loop', 'gateway_remap', 'imager_argv', 'main', 'loop_environment',
           'NODES', 'priority_parameters']

SCAN_SCRIPT = ('teleop_leader', 'config/scan.yaml')
SCAN_DURATION = 18.5  # [s] the scan's last waypoint, and a moment at rest
LATE_POSE_HOLD = 0.5  # [s] past the stalls seen with the machine fully loaded (up to 0.45 s)
MODEL_STEP_RATE = 5.0  # [N/s] at the hand: 17 N/s at the patient, above the scan's 13 (p99)
LINK_TIMEOUT = 0.1  # [s] both ends' watchdogs on a link without jitter (their defaults)
IMAGE = absolute(PROBE_IMAGE)
COMPOSED_MODULE = 'haptic_bringup.composed'
NO_INTRA_PROCESS = '--no-intra-process'  # the composed process's streams through DDS
RECORDER_MODULE = 'haptic_bringup.recorder'
DEFAULT_DOMAIN_ID = 42
DISCOVERY_TIMEOUT = 120.0  # [s] includes imports and, on a cold cache, compiling the kernels
DURATION_GRACE = 3.0  # [s] past --duration before the launcher stops a driver that did not


@dataclasses.dataclass
class LoopConfig:
    """What to run. ``nodes`` may leave some out (a test may stand in for the driver)."""

    nodes: tuple = tuple(NODES)
    composed: bool = False  # haptic_loop's default is True; tests run each node on its own
    intra_process: bool = True  # composed: the nodes' streams handed over in the process
    scene: Optional[str] = None
    experiment: Optional[str] = None
    duration: float = 0.0
    record: Optional[str] = None
    domain_id: int = DEFAULT_DOMAIN_ID
    params_file: Optional[str] = None
    overrides: dict = dataclasses.field(default_factory=dict)
    run_dir: pathlib.Path = pathlib.Path('build/launch')
    python: str = sys.executable
    teleop: Optional[str] = None  # a bilateral scheme: a telerobotic session instead
    link: dict = dataclasses.field(default_factory=dict)  # delay, jitter, loss, ... (s)
    # teleop: the remote site images the probe's view (probe_imager, a process of its own). Off
    # unless asked: on two cores its frames take CPU from the loops (bench/imaging_session.py).
    imaging: bool = False
    remote_domain: Optional[int] = None  # the remote site's DDS domain; None: the next one
    # Composed, the loop's process records itself; False: a recorder process does, as for three
    # processes (the baseline the benchmarks compare it with).
    record_in_process: bool = True
    # The 1 kHz processes' real-time priority (every node but the imager, and the gateways);
    # None: their own (``haptic_util.parameters.RealtimeParams``: 0, normal scheduling).
    thread_priority: Optional[int] = None
    # teleop: each site's gateway is a node of its site's process; False: a process of its own
    # (``site_gateway``), the baseline ``bench/bench_link.py`` measures it against.
    gateway_in_process: bool = True

    @property
    def remote_domain_id(self) -> int:
        """Return the remote site's DDS domain."""
        return self.domain_id + 1 if self.remote_domain is None else self.remote_domain

    @property
    def recorder_process(self) -> bool:
        """Whether a recorder process records the session (three processes), not the loop's."""
        return bool(self.record) and not self.teleop and not (
            self.composed and self.record_in_process)


def add_venv_prefix() -> None:
    """Make this interpreter's prefix an ament prefix, as the PyPI set-up installs into it.

    On a sourced ROS 2 install the prefix is already on AMENT_PREFIX_PATH, or irrelevant.
    """
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    if sys.prefix not in prefixes:
        os.environ['AMENT_PREFIX_PATH'] = os.pathsep.join([*prefixes, sys.prefix])


def loop_environment(domain_id: int, log_dir: pathlib.Path) -> dict:
    """Return the children's environment: our domain, logs in the build dir.

    Discovery stays on this machine unless the user exported another range.
    """
    add_venv_prefix()
    env = dict(os.environ)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env['ROS_DOMAIN_ID'] = str(domain_id)
    env['ROS_LOG_DIR'] = str(log_dir)
    env.setdefault('ROS_HOME', str(log_dir.parent / 'ros_home'))
    env['PYTHONUNBUFFERED'] = '1'
    return env


def node_parameters(config: LoopConfig) -> dict:
    """Every node's parameters: package defaults, then the user's file, then the options."""
    merged = {}
    packages = {entry.package for entry in (*NODES.values(), *TELEOP_NODES.values())}
    for package in sorted(packages):
        share = pathlib.Path(get_package_share_directory(package))
        merged.update(yaml.safe_load((share / 'config' / f'{package}.yaml').read_text()) or {})
    if config.params_file:
        user = yaml.safe_load(pathlib.Path(config.params_file).read_text()) or {}
        for node, section in user.items():
            merged.setdefault(node, {'ros__parameters': {}})
            merged[node]['ros__parameters'].update(section.get('ros__parameters', {}))
    options = {}
    if config.scene:
        for node in ('collision_engine', 'force_renderer', 'wand_driver'):
            options.setdefault(node, {})['scene_file'] = str(config.scene)
    if config.experiment:
        options.setdefault('wand_driver', {})['experiment'] = config.experiment
    if config.duration:
        options.setdefault('wand_driver', {})['duration'] = float(config.duration)
    if config.record and not config.teleop:
        options[LOOP_RECORDER] = {'output': str(pathlib.Path(config.record).resolve())}
    if config.recorder_process:  # it must hear every topic before the session starts
        options.setdefault('wand_driver', {})['wait_for_recorder'] = True
    if config.teleop:
        _teleop_options(config, options)
    if config.thread_priority is not None:
        for node in (*NODES, *TELEOP_NODES, *RECORDERS):
            if node != IMAGER:  # it yields the cores instead (haptic_util.priority)
                options.setdefault(node, {}).update(priority_parameters(config))
    for node, values in [*options.items(), *config.overrides.items()]:
        merged.setdefault(node, {'ros__parameters': {}})
        merged[node]['ros__parameters'].update(values)
    return merged


def priority_parameters(config: LoopConfig) -> dict:
    """Return the ``thread_priority`` the run sets on its 1 kHz nodes, if it sets one."""
    return {} if config.thread_priority is None else {'thread_priority': config.thread_priority}


def _teleop_options(config: LoopConfig, options: dict) -> None:
    """Set the scheme on both ends, and the driver for it: the model is rendered at the device.

    The baseline, direct reflection, runs without the device's own passivity controller. tdpa
    keeps it: its controllers sit at the link's ports and do not see the device hold each force
    over a tick the machine stretched (on a loaded machine, up to +70 mJ given to the hand over
    a scan without it). On regular ticks it never acts (the lockstep scan is bit for bit the
    same with it). While the driver's next pose is late, the answer to the newest one holds until
    it is sent, for at most ``LATE_POSE_HOLD``: an answer that expired inside a stretched tick let
    the hand fall in, and the next one threw it back out (``haptic_wand_driver.answer_deadline``).
    Each new model eases in at ``MODEL_STEP_RATE`` (``haptic_wand_driver.model_easing``): at
    once, every estimate's move since the last jolted the hand (issue 28). Both ends' watchdogs,
    and their admission's bounds on a message's age and lead, wait out the link's spread: its
    jitter, and a delay trace's own rises and falls (``link_emulator.link.delay_spread``,
    ``silence_timeout``). With fixed bounds, over the measured Argentina-Malaga link's worst
    stretch, the follower refused each backlog a rise of the delay released and each early
    bunch a fall brought, hundreds a second, and the robot never reached the patient.
    """
    scheme = config.teleop
    driver = options.setdefault('wand_driver', {})
    if not config.experiment:
        package, relative = SCAN_SCRIPT
        driver['experiment'] = str(pathlib.Path(get_package_share_directory(package)) / relative)
        driver.setdefault('duration', SCAN_DURATION)
    driver['rendering'] = 'local' if scheme == Scheme.MODEL else 'remote'
    driver['passivity'] = scheme != Scheme.DIRECT
    driver['hold_while_late'] = LATE_POSE_HOLD
    driver['model_step_rate'] = MODEL_STEP_RATE
    trace = config.link.get('delay_trace')
    spread = delay_spread(float(config.link.get('jitter', 0.0)),
                          DelayTrace.from_csv(trace) if trace else None)
    bounds = {'link_timeout': silence_timeout(LINK_TIMEOUT, spread),
              'max_stamp_lead': silence_timeout(AdmissionConfig.max_lead, spread)}
    age = silence_timeout(AdmissionConfig.max_age, spread)
    options.setdefault('teleop_leader', {}).update(scheme=scheme, max_feedback_age=age, **bounds)
    options.setdefault('teleop_follower', {}).update(scheme=scheme, max_command_age=age, **bounds)
    if config.record:
        session = pathlib.Path(config.record).resolve()
        options[OPERATOR_RECORDER] = {'output': str(session / 'operator'), 'topics': [
            *OPERATOR_RECORDED, *([IMAGE] if config.imaging else [])]}
        options[REMOTE_RECORDER] = {'output': str(session / 'remote'),
                                    'topics': list(REMOTE_RECORDED), 'prefix': REMOTE_PREFIX}


def site_nodes(config: LoopConfig, site: str) -> tuple:
    """Return the node names of a telerobotic site's process: its nodes, its gateway, its recorder.

    The remote site's imager, if any, is a process of its own (``imager_argv``); so is each
    site's gateway unless ``gateway_in_process``.
    """
    nodes, recorder = ((OPERATOR_SITE, OPERATOR_RECORDER) if site == 'operator' else
                       (REMOTE_SITE, REMOTE_RECORDER))
    gateway = (GATEWAY,) if config.gateway_in_process else ()
    return (*nodes, *gateway, *((recorder,) if config.record else ()))


def gateway_remap(role: str) -> list:
    """Return the ROS arguments that name a site process's gateway node after its role."""
    return ['-r', f'{GATEWAY}:__node:={role}_gateway']


def imager_argv(config: LoopConfig, ros_args: list) -> list:
    """Return the command line of the imager's process, as ``ros2 run`` starts its node."""
    return [config.python, '-m', TELEOP_NODES[IMAGER].module, *ros_args]


def teleop_endpoints(config: LoopConfig) -> dict:
    """Domain → topic → (publishers, subscribers) that make the telerobotic session closed.

    Each site is one process: a stream between its nodes is a DDS endpoint only without
    intra-process delivery. So is each site's recorder, which is in its process and, with that
    delivery, takes what crossed the link through the reader of the node that uses it. The
    recorder's reader of ``/diagnostics`` says it exists: a site builds it last, so its nodes
    then spin (a remote site still starting would miss the operator's short session). The
    imager, in a process of its own, takes the TCP pose over DDS; its image is no stream: the
    gateways and the operator's recorder take it over DDS.
    """
    site = 0 if config.intra_process else 1  # a subscriber in the publisher's process
    recording = site if config.record else 0
    reports = {DIAGNOSTICS: (0, 1)} if config.record else {}
    command, feedback = absolute(TELEOP_COMMAND), absolute(TELEOP_FEEDBACK)
    imaged = config.imaging
    # What crosses is a DDS endpoint at a site unless its gateway hands it over in the process.
    crossing = 0 if config.gateway_in_process and config.intra_process else 1
    return {
        config.domain_id: {absolute(WAND_POSE): (1, site + recording), command: (1, crossing),
                           feedback: (1, crossing * (1 + recording)), **reports,
                           **({IMAGE: (1, int(bool(config.record)))} if imaged else {})},
        config.remote_domain_id: {command: (1, crossing * (1 + recording)),
                                  feedback: (1, crossing),
                                  absolute(ROBOT_TARGET_POSE): (1, site),
                                  absolute(ROBOT_TCP_POSE): (1, site + recording + imaged),
                                  absolute(ROBOT_FT_WRENCH): (1, site + recording), **reports,
                                  **({IMAGE: (1, 1)} if imaged else {})},
    }


def expected_endpoints(config: LoopConfig) -> dict:
    """Topic → (publishers, subscribers) that make the loop closed.

    The driver's own subscription is not among them: it takes the model or the wrench, as its
    device can render, and it waits for that answer itself (it probes the loop end to end). Nor
    is a subscriber that takes its stream in the publisher's process (``intra_process``): the
    loop's own recorder, composed, is one.
    """
    running = set(config.nodes)
    over_dds = 0 if config.composed and config.intra_process else 1
    recording = (1 if config.recorder_process else over_dds) if config.record else 0

    def subscribers(node: str) -> int:
        return recording + over_dds * (node in running)
    endpoints = {}
    if 'wand_driver' in running:
        endpoints[absolute(WAND_POSE)] = (1, subscribers('collision_engine'))
    if 'collision_engine' in running:
        endpoints[absolute(COLLISION_STATE)] = (1, subscribers('force_renderer'))
        endpoints.setdefault(absolute(WAND_POSE), (0, 1))
    if 'force_renderer' in running:
        endpoints[absolute(WAND_WRENCH)] = endpoints[absolute(WAND_CONTACT_MODEL)] = (
            1, recording)
    return endpoints


def _finished(child) -> bool:
    """Whether ``child`` is a driver that ended its experiment, which means the loop ran.

    A driver starts its experiment only once the loop is closed.
    """
    return child.returncode == 0 and child.name in ('wand_driver', 'composed', 'operator')


class Loop:
    """Start the loop, wait until it is closed, and stop it cleanly (a context manager)."""

    def __init__(self, config: LoopConfig) -> None:
        self.config = config
        stamp = time.strftime('%Y%m%d-%H%M%S')
        self.run_dir = pathlib.Path(config.run_dir).resolve() / f'{stamp}-{os.getpid()}'
        self.children = []
        self.startup_time = None
        self._segments_before = shared_memory.segments()

    def __enter__(self) -> 'Loop':
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def start(self) -> None:
        """Start the children and wait until they are up (``startup_time``: how long it took)."""
        self.run_dir.mkdir(parents=True, exist_ok=True)
        env = loop_environment(self.config.domain_id, self.run_dir / 'log')
        params = self.run_dir / 'params.yaml'
        params.write_text(yaml.safe_dump(self._parameters(), sort_keys=False))
        started = time.monotonic()
        self._start_children(env, params)
        self._wait_until_up()
        self.startup_time = time.monotonic() - started

    def _parameters(self) -> dict:
        """Return the parameters file's content: every node's parameters."""
        return node_parameters(self.config)

    def _start_children(self, env: dict, params: pathlib.Path) -> None:
        """Start the loop's processes (or the session's) with the parameters file ``params``."""
        config = self.config
        ros_args = ['--ros-args', '--params-file', str(params)]
        if config.recorder_process:
            env = {**env, **deep_shared_memory_environment()}  # every writer too
            self.children.append(start_child(
                'recorder', [config.python, '-m', RECORDER_MODULE, *ros_args], env))
        if config.teleop:
            self._start_teleop(env, ros_args)
        elif config.composed:
            itself = config.record and not config.recorder_process
            nodes = (*config.nodes, *([LOOP_RECORDER] if itself else []))
            self.children.append(start_child('composed', self._composed(nodes, ros_args), env))
        else:
            for name in config.nodes:
                self.children.append(start_child(
                    name, [config.python, '-m', NODES[name].module, *ros_args], env))

    def _wait_until_up(self) -> None:
        """Wait until the loop is closed (a session: until the operator's domain is up too)."""
        self._wait_for_discovery(self.config.domain_id)

    def _composed(self, nodes, ros_args: list) -> list:
        """Return the command line of one process running ``nodes``."""
        config = self.config
        return [config.python, '-m', COMPOSED_MODULE, *nodes,
                *([] if config.intra_process else [NO_INTRA_PROCESS]), *ros_args]

    def _start_teleop(self, env: dict, ros_args: list) -> None:
        """Start the two sites, each one process in its own domain, and their gateways.

        The operator's site starts its scan as soon as its own loop closes, robot or not, so it
        starts once the remote site is up (under load, the remote site took seconds longer).
        """
        from haptic_bringup.site import loopback_gateway_files, loopback_gateways  # builds on this
        config = self.config
        remote_env = loop_environment(config.remote_domain_id, self.run_dir / 'log')
        gateways = loopback_gateway_files(self.run_dir, link=config.link,
                                          priority=priority_parameters(config))

        def site_args(role: str) -> list:
            in_process = [*gateway_remap(role), '--params-file', str(gateways[role])]
            return [*ros_args, *(in_process if config.gateway_in_process else [])]
        self.children.append(start_child(
            'remote', self._composed(site_nodes(config, 'remote'), site_args('remote')),
            remote_env))
        self._start_imager(ros_args, remote_env)
        if not config.gateway_in_process:
            self.children += loopback_gateways(gateways, config.python, env, remote_env)
        self._wait_for_discovery(config.remote_domain_id)
        self.children.insert(0, start_child(  # the operator's stops first
            'operator', self._composed(site_nodes(config, 'operator'), site_args('operator')),
            env))

    def _start_imager(self, ros_args: list, env: dict) -> None:
        """Start the remote site's imager, a process of its own, if the session images."""
        if self.config.imaging:
            self.children.append(start_child(IMAGER, imager_argv(self.config, ros_args), env))

    def _wait_for_discovery(self, domain_id: int) -> None:
        """Wait until ``domain_id``'s endpoints of the loop or the session are discovered."""
        self._wait_for({domain_id: teleop_endpoints(self.config)[domain_id]
                        if self.config.teleop else expected_endpoints(self.config)})

    def _wait_for(self, endpoints: dict) -> None:
        """Wait until each domain's endpoints are there; stop everything if they never are."""
        missing = []
        for domain_id, expected in endpoints.items():
            watcher = GraphWatcher(domain_id)
            try:
                missing += watcher.wait(expected, DISCOVERY_TIMEOUT,
                                        abort=lambda: self.exited() is not None)
            finally:
                watcher.close()
        dead = self.exited()
        if dead is not None and _finished(dead):
            return  # a short experiment ran to its end before this watcher saw every endpoint
        if dead is not None:
            self.stop(gently=False)  # the others may still be importing
            raise RuntimeError(f'{dead.name} exited with code {dead.returncode} at start-up '
                               '(its error is printed above)')
        if missing:
            self.stop(gently=False)
            raise RuntimeError('the loop did not close within '
                               f'{DISCOVERY_TIMEOUT:.0f} s; missing: {"; ".join(missing)}')

    def exited(self):
        """Return the first child that has exited, or None."""
        return next((c for c in self.children if c.returncode is not None), None)

    def child(self, name: str):
        """Return the running child ``name`` (a node, ``composed`` or ``recorder``)."""
        return next(c for c in self.children if c.name == name)

    def restart(self, name: str):
        """Start child ``name`` again as it was started (after it died); return it.

        The dead child's shared memory goes first (Fast DDS leaves it behind a SIGKILL). A
        process that records itself writes a new bag beside the one it left (``<bag>-2``, ...):
        that one stays for ``haptic_bag recover``.
        """
        old = self.child(name)
        old.process.wait()
        clean_stale_shm(domains=self._domains(), existing=self._segments_before)
        new = start_child(name, self._argv_again(old), old.env)
        self.children[self.children.index(old)] = new
        return new

    def _argv_again(self, child) -> list:
        """Return ``child``'s command line, with a new bag if its process records itself."""
        recorder = next((r for r in RECORDERS if r in child.argv), None)
        if recorder is None:
            return child.argv
        output = node_parameters(self.config)[recorder]['ros__parameters']['output']
        again = next(f'{output}-{n}' for n in itertools.count(2)
                     if not pathlib.Path(f'{output}-{n}').exists())
        params = self.run_dir / f'{recorder}-{pathlib.Path(again).name}.yaml'
        params.write_text(yaml.safe_dump({recorder: {'ros__parameters': {'output': again}}}))
        return [*child.argv, '--params-file', str(params)]

    def pids(self) -> dict:
        return {child.name: child.pid for child in self.children}

    def wait(self, timeout: Optional[float] = None):
        """Wait until a child exits (the driver at the end of its experiment) or ``timeout``."""
        return wait_any_exit(self.children, float('inf') if timeout is None else timeout)

    def stop(self, *, gently: bool = True) -> dict:
        """Stop every child (a recorder process last) and clean shared memory.

        ``gently=False`` for children that may still be starting (see ``stop_children``).
        """
        recorder = [c for c in self.children if c.name == 'recorder']
        others = [c for c in self.children if c.name != 'recorder']
        codes = stop_children(others, gently=gently)
        codes.update(stop_children(recorder, gently=gently))
        self.children = []
        clean_stale_shm(domains=self._domains(), existing=self._segments_before)
        return codes

    def _domains(self) -> list:
        config = self.config
        return [config.domain_id, *([config.remote_domain_id] if config.teleop else [])]


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog='haptic_loop', description=__doc__.split('\n\n')[0],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--separate', action='store_true',
                        help='run the three nodes as three processes (default: one process)')
    parser.add_argument('--scene', help='scene YAML (path or package://pkg/path)')
    parser.add_argument('--experiment', help='simulated operator script: cuboid, cylinder, '
                        'hand, hold, or a waypoint file')
    parser.add_argument('--duration', type=float, default=0.0,
                        help='stop after this many seconds of closed loop (0: until Ctrl-C or '
                        'the end of the experiment)')
    parser.add_argument('--record', metavar='DIR', help='record a rosbag2 (mcap) to DIR')
    parser.add_argument('--teleop', choices=SCHEMES,
                        help='a telerobotic session over an emulated link with this bilateral '
                        'scheme (the experiment defaults to the scripted scan)')
    parser.add_argument('--delay', type=float, default=0.0, help='teleop: one-way link delay [s]')
    parser.add_argument('--jitter', type=float, default=0.0,
                        help='teleop: standard deviation of the delay [s]')
    parser.add_argument('--loss', type=float, default=0.0,
                        help='teleop: probability that a message is lost')
    parser.add_argument('--remote-domain-id', type=int,
                        help='teleop: the remote site\'s DDS domain (default: the next one)')
    parser.add_argument('--delay-trace', metavar='CSV',
                        help='teleop: replay one-way delays from a CSV (time,delay in s)')
    parser.add_argument('--imaging', action='store_true',
                        help='teleop: the remote site images the probe\'s view (probe/image)')
    parser.add_argument('--thread-priority', type=int, metavar='P',
                        help='real-time (SCHED_FIFO) priority of the 1 kHz processes, 1-99, '
                        'for example 50 (default: the nodes\' own, 0: normal scheduling)')
    add_run_arguments(parser, run_dir='build/launch')
    return parser.parse_args(argv)


def add_run_arguments(parser: argparse.ArgumentParser, run_dir: str) -> None:
    """Add the options of where a run goes: its DDS domain, parameters file and folder."""
    parser.add_argument('--domain-id', type=int,
                        default=int(os.environ.get('ROS_DOMAIN_ID', DEFAULT_DOMAIN_ID)))
    parser.add_argument('--params-file', help='YAML with node parameters, as for ros2 run')
    parser.add_argument('--run-dir', default=run_dir,
                        help='where parameters and ROS logs of the run go')


def link_parameters(args: argparse.Namespace) -> dict:
    """Return the emulated link's parameters from the command line."""
    link = {'delay': args.delay, 'jitter': args.jitter, 'loss': args.loss}
    if args.delay_trace:
        link['delay_trace'] = str(pathlib.Path(args.delay_trace).resolve())
    return link


def main(argv=None) -> int:
    """Run a session until it ends or Ctrl-C; a session that ran exits without Python's teardown.

    Its children are stopped and its DDS watchers closed by then; the interpreter's teardown of
    rclpy alone took up to 1.4 s under load (issue 24: a session stops within 2 s).
    """
    args = parse_args(argv)
    config = LoopConfig(composed=not args.separate, scene=args.scene, experiment=args.experiment,
                        duration=args.duration, record=args.record, domain_id=args.domain_id,
                        params_file=args.params_file, run_dir=pathlib.Path(args.run_dir),
                        teleop=args.teleop, link=link_parameters(args),
                        remote_domain=args.remote_domain_id, imaging=args.imaging,
                        thread_priority=args.thread_priority)
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    loop = Loop(config)

    def ready() -> str:
        layout = ('one process' if config.composed else f'{len(config.nodes)} processes')
        if config.teleop:
            layout = (f'{config.teleop} over a {1e3 * args.delay:g} ms link, operator in domain '
                      f'{config.domain_id}, remote site in {config.remote_domain_id}')
        return (f'loop closed in {loop.startup_time:.2f} s ({layout}, domain '
                f'{config.domain_id}); Ctrl-C stops')

    # The driver ends its experiment after ``duration`` and exits; the limit is only a backstop.
    end_process(run_until_stopped(loop, 'haptic_loop', ready, limit=args.duration + DURATION_GRACE
                                  if args.duration else math.inf))


if __name__ == '__main__':
    raise SystemExit(main())
