"""A site in one process: the loop's nodes (or a telerobotic site's) on one EventsExecutor.

One process skips two inter-process hops (and their Python message conversions on both sides),
which halves the loop's latency here. Usage, as for the separate nodes::

    python -m haptic_bringup.composed [wand_driver] [collision_engine] [force_renderer]
        --ros-args --params-file params.yaml

and, for telerobotics, ``wand_driver teleop_leader`` (the operator's site) or ``sim_robot
teleop_follower`` (the remote site).
"""
import importlib
import sys

from haptic_bringup.launcher import NODES, TELEOP_NODES
from haptic_util.executor import run_nodes

__all__ = ['main']


def main(args=None) -> int:
    argv = sys.argv if args is None else args
    ros_start = argv.index('--ros-args') if '--ros-args' in argv else len(argv)
    names = argv[1:ros_start] or list(NODES)
    known = {**NODES, **TELEOP_NODES}
    unknown = [n for n in names if n not in known]
    if unknown:
        print(f'error: unknown node(s) {unknown}; choose from {list(known)}', file=sys.stderr)
        return 2
    classes = [getattr(importlib.import_module(module), cls)
               for _, module, cls in (known[n] for n in names)]
    return run_nodes(classes, argv)


if __name__ == '__main__':
    raise SystemExit(main())
