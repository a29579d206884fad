"""A benchmark's stored results: its rows, with when, where, on which commit and how measured.

``make bench`` runs each benchmark the report shows with ``--json bench/results/<name>.json``
(``run_all.Benchmark.stored``). The report reads those files instead of measuring again, and
each of its sections says which file, when, on which machine and commit, and by what command.
A benchmark joins the report in three small steps (docs/architecture.md): its script takes
``add_option`` and calls ``write``; ``run_all.BENCHMARKS`` marks it ``stored=True``; a section
of ``report_document`` formats ``read(name).results``.

NaN is written as JSON's common extension ``NaN`` (Python reads it back as float NaN).
"""

import dataclasses
import json
import os
from pathlib import Path
import sys

import numpy as np
from report_generator.report_provenance import provenance

__all__ = ['RESULTS', 'Stored', 'add_option', 'describe', 'missing', 'read', 'write']

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / 'bench' / 'results'


@dataclasses.dataclass(frozen=True)
class Stored:
    """One benchmark's last stored run: its results and where they came from."""

    path: Path
    results: object
    measured: dict
    command: str


def add_option(parser) -> None:
    """Add ``--json PATH`` to a benchmark's command line."""
    parser.add_argument('--json', type=Path, metavar='PATH',
                        help='also write the results here, with the date, machine and commit '
                             '(make bench: bench/results/<name>.json, read by the report)')


def _plain(value):
    if dataclasses.is_dataclass(value):
        return dataclasses.asdict(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f'{type(value).__name__} cannot be stored as JSON')


def _command(argv: list) -> str:
    """Return the command as run from the repository: its paths in it relative to it."""
    return ' '.join(['python', *(_shown(Path(a)) if Path(a).is_absolute() else a
                                 for a in [str(Path(argv[0]).resolve()), *argv[1:]])])


def write(path: Path | None, results, argv: list | None = None) -> None:
    """Write ``results`` to ``path`` (nothing when None) with the machine, date and commit.

    ``argv`` is the command that measured them (default ``sys.argv``). The file is replaced
    whole, so a run that fails midway leaves the last complete one.
    """
    if path is None:
        return
    document = {'command': _command(argv or sys.argv), 'measured': provenance(),
                'results': results}
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f'.{path.name}.{os.getpid()}')
    partial.write_text(json.dumps(document, indent=1, default=_plain) + '\n')
    partial.replace(path)
    print(f'results written to {path}', flush=True)


def read(name: str, folder: Path = RESULTS) -> Stored | None:
    """Return benchmark ``name``'s stored run from ``folder``, None if it was never stored."""
    path = folder / f'{name}.json'
    try:
        document = json.loads(path.read_text())
    except FileNotFoundError:
        return None
    return Stored(path, document['results'], document['measured'], document['command'])


def _shown(path: Path) -> str:
    path = path.resolve()
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def describe(stored: Stored) -> str:
    """Say, in one Markdown line, where and when a stored result was measured."""
    m = stored.measured
    load = ' / '.join(f'{v:.1f}' for v in m['load'])
    return (f'*From the last benchmark run, not this one:* `{_shown(stored.path)}`, stored '
            f'{m["date"]} on {m["cpu"]} ({m["cores"]} cores; load average {load} over the last '
            f'1, 5 and 15 minutes as it ended), commit `{m["commit"]}`, by `{stored.command}`. '
            '`make bench` measures it again.')


def missing(name: str, folder: Path = RESULTS) -> str:
    """Say that benchmark ``name`` has no stored result, and how to make one."""
    return (f'*Not measured on this checkout: `{_shown(folder / f"{name}.json")}` is missing; '
            f'`make bench ARGS=\'--only {name}\'` writes it.*')
