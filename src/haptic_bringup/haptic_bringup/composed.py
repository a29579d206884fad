"""The loop in one process: driver, collision engine and force renderer on one EventsExecutor.

One process skips two inter-process hops (and their Python message conversions on both sides),
which halves the loop's latency here. Usage, as for the separate nodes::

    python -m haptic_bringup.composed [wand_driver] [collision_engine] [force_renderer]
        --ros-args --params-file params.yaml
"""
import importlib
import sys

from haptic_bringup.launcher import NODES
from haptic_util.executor import run_nodes

__all__ = ['main']


def main(args=None) -> int:
    argv = sys.argv if args is None else args
    ros_start = argv.index('--ros-args') if '--ros-args' in argv else len(argv)
    names = argv[1:ros_start] or list(NODES)
    unknown = [n for n in names if n not in NODES]
    if unknown:
        print(f'error: unknown node(s) {unknown}; choose from {list(NODES)}', file=sys.stderr)
        return 2
    classes = [getattr(importlib.import_module(module), cls)
               for _, module, cls in (NODES[n] for n in names)]
    return run_nodes(classes, argv)


if __name__ == '__main__':
    raise SystemExit(main())
