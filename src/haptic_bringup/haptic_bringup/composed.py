"""A site in one process: the loop's nodes (or a telerobotic site's) on one EventsExecutor.

One process skips the inter-process hops, and its nodes hand their 1 kHz streams to each other in
the process (``haptic_util.intra_process``), writing to DDS only what another process reads.
``--no-intra-process`` sends them through DDS instead, as separate nodes would: the baseline the
benchmark compares it with. Usage, as for the separate nodes::

    python -m haptic_bringup.composed [--no-intra-process] [wand_driver] [collision_engine]
        [force_renderer] --ros-args --params-file params.yaml

and, for telerobotics, ``wand_driver teleop_leader`` (the operator's site) or ``sim_robot
teleop_follower`` (the remote site). A recorder among the names (``recorder``,
``operator_recorder`` or ``remote_recorder``, each with its parameters under that name) records
the process's streams as they are handed over (``haptic_bringup.process_recorder``); it is built
last, so that it is destroyed last, once every other node has said its last words.
"""
import functools
import importlib
import sys

from haptic_bringup.launcher import NO_INTRA_PROCESS
from haptic_bringup.process_recorder import ProcessRecorder
from haptic_contract.graph import NODES, RECORDERS, TELEOP_NODES
from haptic_util import intra_process
from haptic_util.executor import run_nodes

__all__ = ['main']


def main(args=None) -> int:
    argv = sys.argv if args is None else args
    ros_start = argv.index('--ros-args') if '--ros-args' in argv else len(argv)
    given = argv[1:ros_start]
    names = [name for name in given if name not in (NO_INTRA_PROCESS, *RECORDERS)]
    names = names or list(NODES)
    known = {**NODES, **TELEOP_NODES}
    unknown = [n for n in names if n not in known]
    if unknown:
        print(f'error: unknown node(s) {unknown}; choose from {[*known, *RECORDERS]}',
              file=sys.stderr)
        return 2
    factories = [getattr(importlib.import_module(known[n].module), known[n].cls) for n in names]
    factories += [functools.partial(ProcessRecorder, name) for name in RECORDERS
                  if name in given]
    if NO_INTRA_PROCESS not in given:
        intra_process.enable()
    return run_nodes(factories, argv)


if __name__ == '__main__':
    raise SystemExit(main())
