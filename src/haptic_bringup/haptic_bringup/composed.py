"""A site in one process: the loop's nodes (or a telerobotic site's) on one EventsExecutor.

One process skips the inter-process hops, and its nodes hand their 1 kHz streams to each other in
the process (``haptic_util.intra_process``), writing to DDS only what another process reads.
``--no-intra-process`` sends them through DDS instead, as separate nodes would: the baseline the
benchmark compares it with. Usage, as for the separate nodes::

    python -m haptic_bringup.composed [--no-intra-process] [wand_driver] [collision_engine]
        [force_renderer] --ros-args --params-file params.yaml

and, for telerobotics, ``wand_driver teleop_leader`` (the operator's site) or ``sim_robot
teleop_follower`` (the remote site).
"""
import importlib
import sys

from haptic_bringup.launcher import NO_INTRA_PROCESS, NODES, TELEOP_NODES
from haptic_util import intra_process
from haptic_util.executor import run_nodes

__all__ = ['main']


def main(args=None) -> int:
    argv = sys.argv if args is None else args
    ros_start = argv.index('--ros-args') if '--ros-args' in argv else len(argv)
    given = argv[1:ros_start]
    names = [name for name in given if name != NO_INTRA_PROCESS] or list(NODES)
    known = {**NODES, **TELEOP_NODES}
    unknown = [n for n in names if n not in known]
    if unknown:
        print(f'error: unknown node(s) {unknown}; choose from {list(known)}', file=sys.stderr)
        return 2
    classes = [getattr(importlib.import_module(module), cls)
               for _, module, cls in (known[n] for n in names)]
    if NO_INTRA_PROCESS not in given:
        intra_process.enable()
    return run_nodes(classes, argv)


if __name__ == '__main__':
    raise SystemExit(main())
