"""What the link's door costs: a refused message against a taken one, at the follower.

    .venv/bin/python bench/bench_link_door.py [--messages 20000] [--repeats 5]

A site under attack must shed what it refuses at about the cost of what it takes, or a flood
buys the attacker the site's CPU. Per kind of message, the time (median over repeats, µs per
message) of what the remote site does with one ``teleop/command`` from its bytes: decode it
(``haptic_util.cdr``), then what the node does with its fields (``follower_node.take_command``:
a stranger's refused on its session alone, any other read, checked and admitted).
Beside each refused kind, its ratio to the good command measured in the same run: a command of
another session, one stamped in the future, one at an absurd speed, and malformed bytes that
claim a string longer than the message (which the decoder refuses before reading further).
"""
import argparse
import statistics
import sys
import time

from bench import machine
import numpy as np

from haptic_contract.teleop import Command, CommandLimits, HAND_SPEED
from haptic_contract.teleop_fields import COMMAND, command_fields
from haptic_util.cdr import MalformedMessage
from robot_site.follower import Follower, FollowerConfig
from robot_site.follower_node import take_command
from robot_site.safety import PatientSafety, SafetyConfig
from teleop_protocol.admission import Admission, AdmissionConfig

__all__ = ['main', 'rows']

SESSION = 0x5E55
START = 1_795_000_000.0  # [s] the operator's clock at the first command
PERIOD = 1e-3  # [s]


def _follower() -> Follower:
    """Return a follower that never gives its session up, nor learns its link again.

    So every message of a kind meets the same door, however long the run.
    """
    limits = CommandLimits(np.full(3, -0.4), np.full(3, 0.4), HAND_SPEED)
    return Follower(FollowerConfig('direct', 1500.0),
                    PatientSafety(SafetyConfig(robot_stiffness=1500.0)), limits,
                    admission=Admission(AdmissionConfig(session_timeout=1e9, relearn=1e9)))


def _command(k: int, **changes) -> bytes:
    command = Command(START + k * PERIOD, np.array([0.0, 0.0, -0.01]), np.zeros(3), 0.0,
                      SESSION, k + 1)._replace(**changes)
    return COMMAND.encode(command_fields(command, 'base_link'))


def _kinds(count: int) -> dict:
    """Each kind's messages, numbered on from the ``count`` good ones that come first."""
    later = range(count, 2 * count)
    bad_length = bytearray(_command(0))
    bad_length[12:16] = (10**6).to_bytes(4, 'little')  # the frame's length: past the end
    return {
        'good': [_command(k) for k in later],
        'another session': [_command(k, session=SESSION + 1) for k in later],
        'stamped in the future': [_command(k, stamp=START + k * PERIOD + 10.0) for k in later],
        'absurd speed': [_command(k, velocity=np.array([-1.7e308, 0.0, 0.0])) for k in later],
        'malformed': [bytes(bad_length)] * count,
    }


def _time(follower: Follower, messages: list, first: int) -> tuple[float, dict]:
    """Feed ``messages`` one per period from ``first``; return µs each and the outcomes."""
    outcomes = {}
    start = time.perf_counter()
    for k, data in enumerate(messages, first):
        try:
            fields = COMMAND.decode(data)
        except MalformedMessage:
            outcome = 'malformed'
        else:
            refusal = take_command(follower, START + k * PERIOD + 0.05, fields, 'base_link')
            outcome = 'taken' if refusal is None else refusal.kind
        outcomes[outcome] = outcomes.get(outcome, 0) + 1
    return 1e6 * (time.perf_counter() - start) / len(messages), outcomes


def rows(count: int, repeats: int) -> list[dict]:
    """One row per kind: µs per message (median of ``repeats``), ratio to good, outcomes."""
    kinds = _kinds(count)
    times = {kind: [] for kind in kinds}
    outcomes = {}
    for _ in range(repeats):
        for kind, messages in kinds.items():  # alternated, so drift hits every kind alike
            follower = _follower()
            warm = [_command(k) for k in range(count)]
            _time(follower, warm, 0)  # a session followed, its link learnt
            micros, outcomes[kind] = _time(follower, messages, count)
            times[kind].append(micros)
    good = statistics.median(times['good'])
    return [{'kind': kind, 'us': statistics.median(values),
             'ratio': statistics.median(values) / good, 'outcomes': outcomes[kind]}
            for kind, values in times.items()]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--messages', type=int, default=20_000)
    parser.add_argument('--repeats', type=int, default=5)
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numpy")}')
    print(f'{args.messages} commands of each kind, {args.repeats} alternated repeats; '
          'decode + read + check + admit, one per 1 ms of the operator\'s clock')
    print(f'{"kind":>22} {"us/msg":>8} {"x good":>7}  outcomes')
    for row in rows(args.messages, args.repeats):
        outcomes = ', '.join(f'{k}: {n}' for k, n in row['outcomes'].items())
        print(f'{row["kind"]:>22} {row["us"]:8.2f} {row["ratio"]:7.2f}  {outcomes}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
