"""The report's pure measures: runs, false values, error summaries, angles to the normal.

Expected values are counted or computed by hand in each test.
"""
import math

from fuzzing import examples
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest
from report_generator.report_metrics import (angle_stats, angles_to_normal, error_summary,
                                             false_events, false_samples, runs)


def test_runs_finds_each_stretch_and_drops_short_ones():
    mask = [0, 1, 1, 0, 1, 0, 1, 1, 1]
    assert runs(mask) == [(1, 3), (4, 5), (6, 9)]
    assert runs(mask, min_samples=2) == [(1, 3), (6, 9)]
    assert runs([0, 0]) == []


@settings(max_examples=examples(50), deadline=None)
@given(st.lists(st.booleans(), max_size=40))
def test_runs_cover_exactly_the_true_samples(mask):
    covered = np.zeros(len(mask), dtype=bool)
    for start, stop in runs(mask):
        assert not covered[start:stop].any()
        covered[start:stop] = True
    np.testing.assert_array_equal(covered, np.array(mask, dtype=bool))


def test_false_values_are_large_errors_wrong_signs_and_no_answers():
    truth = np.array([0.010, 0.010, -0.002, 1e-12, 0.005, 0.005, 0.005])
    answer = np.array([0.0105, 0.0125, 0.0001, -1e-12, math.nan, 0.005, 0.0039])
    # 0.5 mm off: fine; 2.5 mm off: false; wrong sign (2.1 mm off too): false; 1e-12 from the
    # surface: sign not judged; no answer: false; exact: fine; 1.1 mm off: false.
    np.testing.assert_array_equal(false_samples(answer, truth),
                                  [False, True, True, False, True, False, True])
    assert false_events(answer, truth) == (3, 4)


def test_a_sign_error_alone_is_false():
    assert false_samples([-1e-6], [1e-6]).tolist() == [True]
    assert false_samples([1e-6], [1e-6], threshold=math.inf).tolist() == [False]


def test_error_summary_skips_unanswered_samples():
    summary = error_summary([1.0, 2.5, math.nan], [1.5, 2.0, 0.0])
    assert summary == {'mean': 0.5, 'max': 0.5, 'unanswered': 1}
    assert math.isnan(error_summary([math.nan], [0.0])['mean'])


def test_angles_to_normal_in_degrees_and_nan_for_weak_forces():
    normal = np.array([[0.0, 0.0, 1.0]] * 4)
    force = np.array([[0.0, 0.0, 2.0], [1.0, 0.0, 1.0], [0.0, -3.0, 0.0], [0.0, 0.0, 1e-9]])
    angles = angles_to_normal(force, normal)
    np.testing.assert_allclose(angles[:3], [0.0, 45.0, 90.0], atol=1e-12)
    assert math.isnan(angles[3])
    assert angles_to_normal([[0.0, 0.0, -1.0]], [[0.0, 0.0, 1.0]])[0] == pytest.approx(180.0)
    assert math.isnan(angles_to_normal([[0.005, 0.0, 0.0]], [[1.0, 0.0, 0.0]],
                                       min_force=0.01)[0])


def test_angle_stats_ignore_nan_and_say_nan_when_nothing_is_left():
    assert angle_stats(np.array([10.0, math.nan, 30.0])) == (20.0, 30.0)
    assert all(math.isnan(v) for v in angle_stats(np.array([math.nan])))
