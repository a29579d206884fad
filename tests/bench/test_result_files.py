"""``bench/result_files.py``: a stored result reads back as written and says where it is from."""
import argparse
from dataclasses import dataclass
import json
import math
from pathlib import Path

from bench.result_files import add_option, describe, missing, read, RESULTS, write
import numpy as np
import pytest


@dataclass(frozen=True)
class Row:
    stiffness: float
    mode: str


def test_rows_read_back_as_written_with_the_machine_date_commit_and_command(tmp_path: Path):
    path = tmp_path / 'results' / 'sweep.json'
    rows = {'bound': np.float64(1234.5), 'rows': [Row(100.0, 'on'), Row(1e3, 'off')],
            'counts': np.arange(3), 'missing': math.nan}
    write(path, rows, ['/somewhere/bench/sweep.py', '--points', '3', '--json',
                       str(RESULTS / 'sweep.json')])
    stored = read('sweep', tmp_path / 'results')
    assert stored.path == path
    assert stored.results['bound'] == 1234.5
    assert stored.results['rows'] == [{'stiffness': 100.0, 'mode': 'on'},
                                      {'stiffness': 1000.0, 'mode': 'off'}]
    assert stored.results['counts'] == [0, 1, 2]
    assert math.isnan(stored.results['missing'])
    assert stored.command == ('python /somewhere/bench/sweep.py --points 3 --json '
                              'bench/results/sweep.json')
    assert {'date', 'cpu', 'cores', 'commit', 'load', 'versions'} <= set(stored.measured)
    assert len(stored.measured['load']) == 3


def test_a_benchmark_never_stored_reads_as_none_and_says_how_to_store_it(tmp_path: Path):
    assert read('loop', tmp_path) is None
    text = missing('loop', tmp_path)
    assert f'`{tmp_path / "loop.json"}` is missing' in text
    assert "`make bench ARGS='--only loop'`" in text


def test_the_description_names_the_file_the_date_the_machine_the_commit_and_the_command(
        tmp_path: Path):
    write(tmp_path / 'loop.json', [1, 2], ['bench/bench_loop.py', '--json', 'x'])
    stored = read('loop', tmp_path)
    text = describe(stored)
    m = stored.measured
    for part in (str(tmp_path / 'loop.json'), m['date'], m['cpu'], f'{m["cores"]} cores',
                 m['commit'], stored.command, 'not this one'):
        assert part in text


def test_without_a_path_nothing_is_written(tmp_path: Path):
    write(None, [1, 2])
    assert not list(tmp_path.iterdir())


def test_results_that_cannot_be_stored_raise_and_leave_the_last_stored_run(tmp_path: Path):
    path = tmp_path / 'loop.json'
    write(path, [1], ['bench/bench_loop.py'])
    before = path.read_text()
    with pytest.raises(TypeError, match='object cannot be stored as JSON'):
        write(path, [object()], ['bench/bench_loop.py'])
    assert path.read_text() == before
    assert [p.name for p in tmp_path.iterdir()] == ['loop.json']
    assert json.loads(before)['results'] == [1]


def test_the_option_is_json_path():
    parser = argparse.ArgumentParser()
    add_option(parser)
    assert parser.parse_args(['--json', 'a/b.json']).json == Path('a/b.json')
    assert parser.parse_args([]).json is None
