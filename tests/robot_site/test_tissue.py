"""The Hunt–Crossley tissue against its closed form, its defaults against the clinical range."""
import math

import numpy as np
import pytest

from robot_site.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from robot_site.tissue import ABDOMEN, HuntCrossley, PlaneSurface, Tissue

LAW = HuntCrossley(stiffness=3000.0, exponent=1.5, damping=900.0)


@pytest.mark.parametrize('depth, rate', [(0.01, 0.0), (0.02, 0.05), (0.015, -0.1), (0.03, 0.2)])
def test_the_force_is_the_hunt_crossley_closed_form(depth, rate):
    expected = 3000.0 * depth ** 1.5 + 900.0 * depth ** 1.5 * rate
    assert LAW.normal_force(depth, rate) == pytest.approx(expected, rel=1e-12)


def test_the_tissue_never_pulls():
    assert LAW.normal_force(-0.01, 0.0) == 0.0
    assert LAW.normal_force(0.0, 5.0) == 0.0
    assert LAW.normal_force(0.01, -10.0) == 0.0  # withdrawn faster than k / λ = 3.3 m/s


def test_the_abdomen_gives_10_n_at_15_to_20_mm_and_stays_in_the_clinical_range():
    assert 1.2 <= ABDOMEN.exponent <= 1.5
    assert 0.015 <= ABDOMEN.static_depth(10.0) <= 0.020
    assert 5.0 <= ABDOMEN.normal_force(0.010, 0.0) <= 20.0  # 5–20 N at 10–30 mm
    assert 5.0 <= ABDOMEN.normal_force(0.030, 0.0) <= 35.0


def test_static_depth_inverts_the_spring_and_the_tangents_are_its_derivatives():
    depth = LAW.static_depth(7.0)
    assert LAW.normal_force(depth, 0.0) == pytest.approx(7.0, rel=1e-12)
    step = 1e-7
    slope = (LAW.normal_force(depth + step, 0.0) - LAW.normal_force(depth - step, 0.0)) / 2 / step
    assert LAW.tangent_stiffness(depth) == pytest.approx(slope, rel=1e-6)
    assert LAW.tangent_damping(depth) == pytest.approx(
        LAW.normal_force(depth, 1.0) - LAW.normal_force(depth, 0.0), rel=1e-12)


def test_the_force_points_along_the_outward_normal_of_a_tilted_plane():
    normal = np.array([0.0, 0.6, 0.8])
    tissue = Tissue(LAW, PlaneSurface([0.0, 0.0, 0.1], normal))
    inside = np.array([0.0, 0.0, 0.1]) - 0.02 * normal + [0.3, -0.8 * 0.05, 0.6 * 0.05]
    force = tissue(inside, -0.05 * normal)
    np.testing.assert_allclose(force, LAW.normal_force(0.02, 0.05) * normal, rtol=1e-12)
    np.testing.assert_array_equal(tissue(inside + 0.03 * normal, np.zeros(3)), np.zeros(3))


def test_a_robot_pressing_the_abdomen_rests_where_its_spring_meets_the_tissue():
    robot_stiffness = 1500.0
    robot = ImpedanceRobot(ImpedanceRobotConfig(stiffness=robot_stiffness),
                           environment=Tissue(ABDOMEN))
    robot.read(0.0)
    robot.command([0.0, 0.0, -0.03])
    state = robot.read(3.0)
    depth = -state.position[2]
    # At rest the spring's pull equals the tissue's push.
    tissue_force = ABDOMEN.normal_force(depth, 0.0)
    assert robot_stiffness * (0.03 - depth) == pytest.approx(tissue_force, rel=1e-6)
    assert state.external_force[2] == pytest.approx(ABDOMEN.normal_force(depth, 0.0), rel=1e-6)


@pytest.mark.parametrize('fields, message', [
    (dict(stiffness=0.0), 'stiffness must be finite > 0'),
    (dict(exponent=0.5), 'exponent must be finite >= 1'),
    (dict(damping=-1.0), 'damping must be finite >= 0'),
    (dict(damping=math.nan), 'damping must be finite >= 0'),
])
def test_bad_laws_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        HuntCrossley(**{**dict(stiffness=1.0, exponent=1.0, damping=0.0), **fields})


def test_bad_planes_and_forces_are_refused():
    with pytest.raises(ValueError, match='normal must not be zero'):
        PlaneSurface([0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match='point must be 3 finite numbers'):
        PlaneSurface([0, math.nan, 0], [0, 0, 1])
    with pytest.raises(ValueError, match='force must be finite >= 0'):
        LAW.static_depth(-1.0)
