"""``bench/run_all.py``: it lists every benchmark, and a failing one does not stop the rest.

No real benchmark runs here: the list is checked against the files in ``bench/``, and the
runner is driven on throw-away scripts.
"""
from pathlib import Path
import re

from bench.run_all import BENCH, Benchmark, BENCHMARKS, run, summary

NOT_BENCHMARKS = {'run_all.py', 'loop_floor.py'}  # the runner, and the processes bench_loop.py
# starts


def runnable_scripts() -> set[str]:
    """Every file in bench/ with a ``__main__`` guard: the scripts one can run."""
    return {path.name for path in BENCH.glob('*.py')
            if "if __name__ == '__main__':" in path.read_text()}


def test_every_benchmark_script_in_bench_is_run_once():
    listed = [b.script for b in BENCHMARKS]
    assert len(listed) == len(set(listed))
    assert set(listed) == runnable_scripts() - NOT_BENCHMARKS
    assert len({b.name for b in BENCHMARKS}) == len(BENCHMARKS)


def test_quick_options_are_options_of_the_script_itself():
    for benchmark in BENCHMARKS:
        source = (BENCH / benchmark.script).read_text()
        options = {f for f in benchmark.quick if f.startswith('--')}
        declared = set(re.findall(r"add_argument\('(--[\w-]+)'", source))
        assert options <= declared, benchmark.script


def test_a_failing_script_is_reported_and_the_next_still_runs(tmp_path: Path, capfd):
    (tmp_path / 'fails.py').write_text('import sys\nsys.exit(3)\n')
    (tmp_path / 'works.py').write_text('import sys\nprint("argv", sys.argv[1:])\n')
    benchmarks = [Benchmark('fails', 'fails.py'), Benchmark('works', 'works.py', ('--n', '2'))]
    outcomes = run(benchmarks, quick=True, folder=tmp_path)
    assert [o.returncode for o in outcomes] == [3, 0]
    assert "argv ['--n', '2']" in capfd.readouterr().out
    lines = summary(outcomes).splitlines()
    assert lines[0].startswith('fails  fails.py') and 'failed (exit 3)' in lines[0]
    assert lines[1].startswith('works  works.py') and ' ok, ' in lines[1]


def test_without_quick_the_script_gets_no_arguments(tmp_path: Path, capfd):
    (tmp_path / 'works.py').write_text('import sys\nprint("argv", sys.argv[1:])\n')
    run([Benchmark('works', 'works.py', ('--n', '2'))], folder=tmp_path)
    assert 'argv []' in capfd.readouterr().out


def test_a_stored_benchmark_writes_its_results_on_a_full_run_only(tmp_path: Path, capfd):
    (tmp_path / 'works.py').write_text('import sys\nprint("argv", sys.argv[1:])\n')
    stored = Benchmark('works', 'works.py', ('--n', '2'), stored=True)
    run([stored], folder=tmp_path, results=tmp_path / 'results')
    assert f"argv ['--json', '{tmp_path / 'results' / 'works.json'}']" in capfd.readouterr().out
    run([stored], quick=True, folder=tmp_path, results=tmp_path / 'results')
    assert "argv ['--n', '2']" in capfd.readouterr().out


def test_every_stored_benchmark_takes_json_and_writes_its_results():
    for benchmark in BENCHMARKS:
        source = (BENCH / benchmark.script).read_text()
        takes = 'result_files.add_option(parser)' in source
        writes = 'result_files.write(args.json' in source
        assert takes == writes == benchmark.stored, benchmark.script
