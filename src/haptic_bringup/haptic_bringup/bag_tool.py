"""``haptic_bag info|recover DIR``: bag tools for machines without ``ros2 bag``.

DIR is a bag, or a session's folder of bags (a telerobotic session's ``operator`` and
``remote``): ``info`` lists each topic's count, ``recover`` rebuilds each bag in it that a killed
recorder left (``haptic_bringup.bag.recover``). A command of its own, apart from ``bag``, which
the recorders and the session readers build on.
"""
import argparse
import pathlib
import sys

from haptic_bringup.bag import killed_bags, recover, typestore_with
from haptic_bringup.recorder import custom_definitions
from haptic_bringup.session import topic_counts

__all__ = ['main']


def main(argv=None) -> int:
    """Run ``haptic_bag``; exit 1 with one line naming the bag when it cannot."""
    parser = argparse.ArgumentParser(prog='haptic_bag', description=__doc__.split('\n')[0])
    parser.add_argument('command', choices=['info', 'recover'])
    parser.add_argument('bag', type=pathlib.Path)
    args = parser.parse_args(argv)
    try:
        if args.command == 'recover':
            killed = killed_bags(args.bag)
            if not killed:
                raise ValueError('no bag without metadata.yaml to recover')
            for bag in killed:
                recovered = recover(bag, typestore_with(custom_definitions()))
                print(f'recovered {bag} into {recovered}')
            args.bag = recovered if killed == [args.bag] else args.bag
        for topic, count in sorted(topic_counts(args.bag).items()):
            print(f'{topic}: {count} messages')
    except (ValueError, OSError) as error:
        print(f'haptic_bag: {args.bag}: {error}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
