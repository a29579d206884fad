"""Scripts: minimum-jerk waypoints, waypoint files, and the paper's three tapping experiments."""

from functools import lru_cache

from fuzzing import examples
from ground_truth.wand import Box, Cylinder, HalfSpace, wall_force
from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from haptic_wand_driver.device import Workspace
from haptic_wand_driver.simulated import SimulatedWand
from simulated_operator.hand import OperatorHand
from simulated_operator.scripts import (
    cuboid_face_tapping, cylinder_side_tapping, hand_dorsum_tapping, probe_sweep, ScriptError,
    TappingScript, TappingSite, WaypointScript)

TICK = 1e-3
THIRTY_DEGREES = np.radians(30.0)
LEG = np.array([0.1, -0.05, 0.02, 0.2, -0.1])


def min_jerk(tau):
    """Flash & Hogan's rest-to-rest profile, written out as a polynomial."""
    return 10 * tau ** 3 - 15 * tau ** 4 + 6 * tau ** 5


def one_leg():
    return WaypointScript.from_rows([(1.0, 0.0, 0.0, 0.0, 0.0, 0.0), (3.0, *LEG)])


@pytest.mark.parametrize('t', [1.0, 1.3, 2.0, 2.5, 3.0])
def test_a_leg_follows_the_minimum_jerk_profile(t):
    np.testing.assert_allclose(one_leg().target(t).coordinates, min_jerk((t - 1.0) / 2.0) * LEG,
                               atol=1e-15)


def test_rest_before_and_after_and_at_waypoints():
    script = one_leg()
    for t in (0.0, 1.0, 3.0, 7.0):
        np.testing.assert_array_equal(script.target(t).rates, np.zeros(5))
    np.testing.assert_array_equal(script.target(0.0).coordinates, np.zeros(5))
    np.testing.assert_array_equal(script.target(9.0).coordinates, LEG)
    assert script.duration == 3.0


@settings(max_examples=examples(40), deadline=None)
@given(st.floats(0.01, 4.99))
def test_rates_are_the_derivative_of_the_coordinates(t):
    script = WaypointScript.from_rows([(0.0, 0.0, 0.0, 0.0), (2.0, 0.05, 0.0, -0.05),
                                       (2.5, 0.05, 0.0, -0.05), (5.0, -0.02, 0.03, 0.0, 0.1, 0.2)])
    h = 1e-6
    numeric = (script.target(t + h).coordinates - script.target(t - h).coordinates) / (2 * h)
    np.testing.assert_allclose(script.target(t).rates, numeric, atol=1e-6)


def test_yaml_and_csv_files_give_the_same_script(tmp_path):
    yaml_file = tmp_path / 'path.yaml'
    yaml_file.write_text('waypoints:\n'
                         '  - {t: 0.0, x: 0.0, y: 0.0, z: 0.0}\n'
                         '  - {t: 1.5, x: 0.01, y: 0.02, z: -0.05, yaw: 0.2}\n')
    csv_file = tmp_path / 'path.csv'
    csv_file.write_text('t,x,y,z,roll,yaw\n0,0,0,0,0,0\n1.5,0.01,0.02,-0.05,0,0.2\n')
    expected = np.array([[0.0, 0.0, 0.0, 0.0, 0.0], [0.01, 0.02, -0.05, 0.0, 0.2]])
    for path in (yaml_file, csv_file):
        script = WaypointScript.from_file(path)
        np.testing.assert_array_equal(script.times, [0.0, 1.5])
        np.testing.assert_array_equal(script.coordinates, expected)


@pytest.mark.parametrize('text, expected', [
    ('waypoints:\n  - {t: 0, x: 0, y: 0, z: 0}\n  - {t: 1, x: 0, y: 0, z: 0, yw: 1}\n',
     r'waypoints\[1\]: unknown field\(s\) yw'),
    ('waypoints:\n  - {t: 0, x: 0, y: 0}\n', r'waypoints\[0\]: missing field\(s\) z'),
    ('waypoints:\n  - {t: 0, x: 0, y: 0, z: fast}\n', r'waypoints\[0\]\.z: expected a number'),
    ('waypoints:\n  - {t: 1, x: 0, y: 0, z: 0}\n  - {t: 1, x: 0, y: 0, z: 0}\n',
     'pose 1 .*does not increase'),
    ('waypoints:\n  - {t: 0, x: 0, y: 0, z: 0}\n  - {t: 1, x: 0, y: 0, z: 0.5}\n',
     'waypoint 1: .*outside the workspace'),
    ('waypoints:\n  - {t: 0, x: 0, y: 0, z: 0, yaw: 0.6}\n', 'waypoint 0: .*outside'),
    ('path: []\n', 'expected a mapping with key "waypoints"'),
    ('waypoints: [\n', 'not valid YAML'),
])
def test_bad_yaml_waypoints_name_the_file_and_field(tmp_path, text, expected):
    path = tmp_path / 'bad.yaml'
    path.write_text(text)
    with pytest.raises(ScriptError, match=expected) as raised:
        WaypointScript.from_file(path)
    assert str(path) in str(raised.value)


def test_bad_waypoint_files_name_the_file(tmp_path):
    for path, expected in ((tmp_path / 'missing.yaml', 'cannot read'),
                           (tmp_path / 'missing.csv', 'cannot read'),
                           (tmp_path / 'path.json', 'unsupported waypoint file type')):
        with pytest.raises(ScriptError, match=expected) as raised:
            WaypointScript.from_file(path)
        assert str(path) in str(raised.value)


@pytest.mark.parametrize('rows, expected', [([], 'empty'), ([(0.0, 0.0, 0.0)], 'waypoint 0'),
                                            ([(-1.0, 0.0, 0.0, 0.0)], 'negative'),
                                            ([(0.0, 0.0, np.nan, 0.0)], 'finite')])
def test_bad_waypoint_rows_are_refused(rows, expected):
    with pytest.raises(ScriptError, match=expected):
        WaypointScript.from_rows(rows)


# The paper's objects as placed in the project's scenes, as exact analytic shapes.
EXPERIMENTS = {
    'hand': (hand_dorsum_tapping, HalfSpace([0.0, 0.0, -0.056], [0.0, 0.0, 1.0]), 11),
    'cylinder': (cylinder_side_tapping, Cylinder([0.0, 0.0, -0.075], 0.025, 0.1), 9),
    'cuboid': (cuboid_face_tapping, Box([0.0, 0.0, -0.075], [0.2, 0.1, 0.1]), 9),
}


def entries(inside):
    """Indices where a boolean trace turns True."""
    inside = np.asarray(inside)
    return np.flatnonzero(inside[1:] & ~inside[:-1]) + 1


def crossing_time(script, shape, before, after):
    """Bisect the instant the target crosses the surface, between two sampled times."""
    for _ in range(60):
        middle = 0.5 * (before + after)
        if shape.signed_distance(script.target(middle).coordinates[:3]) >= 0.0:
            before = middle
        else:
            after = middle
    return 0.5 * (before + after)


@pytest.mark.parametrize('name', EXPERIMENTS)
def test_target_taps_each_site_once_at_the_approach_speed(name):
    factory, shape, taps = EXPERIMENTS[name]
    script = factory(shape.project)
    times = np.arange(0.0, 10.5, TICK)
    coordinates = np.array([script.target(t).coordinates for t in times])
    np.testing.assert_array_equal(coordinates[0], np.zeros(5))
    assert script.duration == pytest.approx(10.0)
    lower, upper = Workspace().coordinate_bounds
    assert np.all(coordinates >= lower) and np.all(coordinates <= upper)
    assert np.all(np.abs(coordinates[:, 4]) <= THIRTY_DEGREES)
    inside = [shape.signed_distance(point) < 0.0 for point in coordinates[:, :3]]
    crossings = entries(inside)
    assert len(crossings) == taps
    for index in crossings:
        t = crossing_time(script, shape, times[index - 1], times[index])
        target = script.target(t)
        normal = shape.outward_normal(target.coordinates[:3])
        assert -np.dot(target.rates[:3], normal) == pytest.approx(0.2, rel=1e-6)


@lru_cache(maxsize=None)
def closed_loop(name):
    """Ten seconds of the simulated wand tapping the object, the wall force computed here."""
    factory, shape, _ = EXPERIMENTS[name]
    wand = SimulatedWand(operator=OperatorHand(factory(shape.project)))
    distances, approach_speeds = [], []
    for now in np.arange(0.0, 10.5, TICK):
        state = wand.read(now)
        distance = shape.signed_distance(state.position)
        normal = shape.outward_normal(state.position)
        distances.append(distance)
        approach_speeds.append(-np.dot(state.linear_velocity, normal))
        wand.apply(wall_force(shape, state.position, state.linear_velocity), np.zeros(3))
    return np.array(distances), np.array(approach_speeds)


@pytest.mark.parametrize('name', EXPERIMENTS)
def test_closed_loop_makes_the_paper_contacts_at_about_point_two_metres_per_second(name):
    taps = EXPERIMENTS[name][2]
    distances, approach_speeds = closed_loop(name)
    inside = distances < 0.0
    starts = entries(inside)
    ends = entries(~inside)
    assert 9 <= len(starts) <= 18 and len(starts) == taps
    assert len(ends) == len(starts) and np.all(ends > starts)
    np.testing.assert_array_less(0.15, approach_speeds[starts])
    np.testing.assert_array_less(approach_speeds[starts], 0.3)
    durations = (ends - starts) * TICK
    np.testing.assert_array_less(0.3, durations)
    np.testing.assert_array_less(durations, 0.6)


@pytest.mark.parametrize('name', EXPERIMENTS)
def test_closed_loop_tip_rests_on_the_surface_not_at_the_target(name):
    distances, _ = closed_loop(name)
    starts, ends = entries(distances < 0.0), entries(distances >= 0.0)
    assert distances.min() > -0.01
    for start, end in zip(starts, ends):
        settled = distances[start:end][-50:]
        assert np.all((-0.005 < settled) & (settled < 0.0))


def test_cylinder_sites_turn_the_wand_to_face_the_surface():
    script = cylinder_side_tapping(EXPERIMENTS['cylinder'][1].project)
    np.testing.assert_allclose([site.yaw for site in script.sites],
                               np.radians(np.linspace(-24.0, 24.0, 9)), atol=1e-12)


def test_cuboid_sites_lie_on_the_minus_x_face():
    script = cuboid_face_tapping(EXPERIMENTS['cuboid'][1].project)
    for site in script.sites:
        assert site.point[0] == pytest.approx(-0.1)
        np.testing.assert_allclose(site.normal, [-1.0, 0.0, 0.0])
        assert site.yaw == 0.0


def test_denser_tapping_fits_more_contacts():
    shape = EXPERIMENTS['cuboid'][1]
    script = cuboid_face_tapping(shape.project, taps=14, dwell=0.1, clearance=0.012)
    inside = [shape.signed_distance(script.target(t).coordinates[:3]) < 0.0
              for t in np.arange(0.0, 10.0, TICK)]
    assert len(entries(inside)) == 14


def test_too_many_taps_for_the_duration_is_refused():
    with pytest.raises(ScriptError, match='18 taps'):
        cuboid_face_tapping(EXPERIMENTS['cuboid'][1].project, taps=18)


def test_sites_outside_the_workspace_are_refused():
    narrow = Workspace(lower=[-0.11, -0.15, -0.15], upper=[0.15, 0.15, 0.1])
    with pytest.raises(ScriptError, match='tap 0: approach point .* outside the workspace'):
        cuboid_face_tapping(EXPERIMENTS['cuboid'][1].project, workspace=narrow)


def test_unusable_projection_is_refused_naming_the_tap():
    with pytest.raises(ScriptError, match='tap 0: project'):
        hand_dorsum_tapping(lambda point: (point, np.zeros(3)))


def test_bad_aim_points_and_sites_are_refused():
    with pytest.raises(ScriptError, match='aim_points'):
        hand_dorsum_tapping(EXPERIMENTS['hand'][1].project, aim_points=[[0.0, 0.0]])
    with pytest.raises(ScriptError, match='at least one site'):
        TappingScript([])
    with pytest.raises(ScriptError, match='depth'):
        TappingScript([TappingSite([0.0, 0.0, -0.05], [0.0, 0.0, 1.0])], depth=-0.01)


# The probe sweep.

def flat_floor(point):
    """The plane z = -0.025 m, seen from above."""
    return np.array([point[0], point[1], -0.025]), np.array([0.0, 0.0, 1.0])


def test_the_probe_sweep_presses_rolls_slides_and_yaws_within_ten_seconds():
    script = probe_sweep(flat_floor)
    rows = np.column_stack((script.times, script.coordinates))
    assert script.duration <= 10.0
    pressed = rows[(rows[:, 0] >= 1.8) & (rows[:, 0] <= 9.0)]
    np.testing.assert_allclose(pressed[:, 3], -0.025 - 0.04)
    twenty = np.radians(20.0)
    assert pressed[:, 4].max() == pytest.approx(twenty) and pressed[:, 4].min() == -twenty
    assert pressed[:, 5].max() == pytest.approx(twenty) and pressed[:, 5].min() == -twenty
    assert pressed[:, 1].max() == pytest.approx(0.02) and pressed[:, 1].min() == -0.02
    np.testing.assert_allclose(rows[[1, -1], 3], -0.02)  # 5 mm above, before and after
    # While rolled it holds still; while yawed it slides.
    rolled = pressed[pressed[:, 4] != 0.0]
    assert np.all(rolled[:, 1] == 0.0) and np.all(rolled[:, 5] == 0.0)


def test_the_probe_sweep_follows_a_curved_surface_below_each_position():
    def dome(point):  # a sphere of radius 0.2 m whose top is at z = -0.025
        centre = np.array([0.0, 0.0, -0.225])
        normal = (point - centre) / np.linalg.norm(point - centre)
        return centre + 0.2 * normal, normal
    rows = probe_sweep(dome, depth=0.01).coordinates
    for x, z in rows[2:-1, [0, 2]]:
        surface = -0.225 + 0.2 * 0.225 / np.hypot(x, 0.225)  # along the ray from the centre
        assert z == pytest.approx(surface - 0.01, abs=1e-12)
    assert rows[:, 2].min() < rows[2, 2]  # lower at the sides than at the top


def test_the_probe_sweep_refuses_a_surface_that_does_not_face_up():
    def wall(point):
        return np.array([0.1, point[1], point[2]]), np.array([-1.0, 0.0, 0.0])
    with pytest.raises(ScriptError, match='probe sweep: no upward surface below'):
        probe_sweep(wall)
