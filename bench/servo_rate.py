"""The device's servo rate: what one servo period costs, and how stiff a wall it renders cleanly.

    .venv/bin/python bench/servo_rate.py [--rates 1000 2000 4000 10000]
                                         [--stiffness 160 1000 5000 20000 100000 500000]
                                         [--json PATH]

The simulated wand taps a wall (``bench/taps.py``: pushed 10 mm in, held,
lifted), the model of each pose reaching the device one 1 ms tick later. Per servo rate, with the
contact rendered on the device: the cost of one servo period (the wand's dynamics and the local
law, median and p99 in µs, over every tick of every tap; in the wand's Python loop, observed
period by period, and compiled as the driver runs it, ``servo_loop``), the highest stiffness
that stays at one contact per tap with no energy given to the hand, and the felt latency (from
the tip crossing into the wall to the first period with a force). Beside it, remote rendering
(the wrench of the tick-old pose, held) at the same stiffnesses: its contacts per tap and
latency, the baseline.
"""
import argparse

from bench import machine, result_files
from bench.taps import servo_cost, tap
import numpy as np

__all__ = ['main', 'rows']


def rows(rates, stiffnesses) -> list[dict]:
    """One row per servo rate: cost, the stiffest clean wall, latency; remote beside it."""
    table = []
    for rate in rates:
        local = {k: tap(k, local=True, servo_rate=rate) for k in stiffnesses}
        remote = {k: tap(k, local=False, servo_rate=rate) for k in stiffnesses}
        costs = np.concatenate([r.substep_cost for r in local.values()])
        compiled = np.concatenate([servo_cost(k, servo_rate=rate) for k in stiffnesses])
        clean = [k for k, r in local.items() if r.contacts == 1 and r.work <= 0.0]
        table.append({
            'rate': rate, 'cost_p50_us': 1e6 * float(np.median(costs)),
            'cost_p99_us': 1e6 * float(np.percentile(costs, 99)),
            'compiled_p50_us': 1e6 * float(np.median(compiled)),
            'compiled_p99_us': 1e6 * float(np.percentile(compiled, 99)),
            'stiffest_clean': max(clean, default=float('nan')),
            'latency_ms': 1e3 * float(np.median([r.felt_latency for r in local.values()])),
            'local_contacts': {k: r.contacts for k, r in local.items()},
            'remote_contacts': {k: r.contacts for k, r in remote.items()},
            'remote_latency_ms': 1e3 * float(np.median([r.felt_latency
                                                        for r in remote.values()]))})
    return table


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--rates', nargs='+', type=float, default=[1e3, 2e3, 4e3, 1e4])
    parser.add_argument('--stiffness', nargs='+', type=float,
                        default=[1e3, 1e4, 1e5, 2e5, 5e5, 1e6])
    result_files.add_option(parser)
    args = parser.parse_args(argv)
    print(f'machine: {machine.line("numpy")}')
    print(f'{"servo Hz":>9} {"Python p50 us":>13} {"p99 us":>7} {"compiled p50":>12} '
          f'{"p99":>5} {"stiffest clean N/m":>18} '
          f'{"felt ms":>8}  contacts per tap, local | remote, at K = '
          f'{", ".join(f"{k:g}" for k in args.stiffness)}')
    table = rows(args.rates, args.stiffness)
    for row in table:
        local = ' '.join(str(c) for c in row['local_contacts'].values())
        remote = ' '.join(str(c) for c in row['remote_contacts'].values())
        print(f'{row["rate"]:9.0f} {row["cost_p50_us"]:13.1f} {row["cost_p99_us"]:7.1f} '
              f'{row["compiled_p50_us"]:12.1f} {row["compiled_p99_us"]:5.1f} '
              f'{row["stiffest_clean"]:18g} {row["latency_ms"]:8.3f}  {local} | {remote} '
              f'(remote felt {row["remote_latency_ms"]:.2f} ms)', flush=True)
    result_files.write(args.json, table)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
