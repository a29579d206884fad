"""Both ends of the bilateral schemes, and the map between the wand and the robot."""
import numpy as np
import pytest

from remote_probe.follower import Follower, FollowerConfig
from remote_probe.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from remote_probe.leader import Leader, LeaderConfig
from remote_probe.model_estimation import ContactModelEstimator
from remote_probe.safety import PatientSafety, SafetyConfig
from remote_probe.teleop import Command, Feedback, RemotePlane
from remote_probe.tissue import HuntCrossley, PlaneSurface, Tissue
from remote_probe.virtual_coupling import CouplingConfig
from remote_probe.workspace_map import WorkspaceMap

UP = np.array([0.0, 0.0, 1.0])


def feedback(stamp, force=(0.0, 0.0, 5.0), *, echo=0.0, hold=0.0, energy=0.0, plane=None):
    return Feedback(stamp, echo, hold, np.array(force), np.zeros(3), energy, plane)


def follower(scheme='direct', **safety):
    config = FollowerConfig(scheme, robot_stiffness=1500.0)
    return Follower(config, PatientSafety(SafetyConfig(robot_stiffness=1500.0, **safety)),
                    ContactModelEstimator())


def test_the_map_scales_motion_and_its_inverse_undoes_it():
    workspace = WorkspaceMap(0.5, 0.3, wand_start=[0.1, 0.0, 0.0], robot_start=[0.0, 0.2, 0.0])
    np.testing.assert_allclose(workspace.to_robot([0.3, 0.0, -0.1]), [0.1, 0.2, -0.05])
    np.testing.assert_allclose(workspace.to_wand([0.1, 0.2, -0.05]), [0.3, 0.0, -0.1])
    np.testing.assert_allclose(workspace.velocity_to_robot([0.2, 0.0, 0.0]), [0.1, 0.0, 0.0])
    assert workspace.felt_gain(1000.0) == pytest.approx(0.3 * 0.5 * 1000.0)


def test_the_clutch_holds_the_robot_and_lets_go_without_a_jump():
    workspace = WorkspaceMap(1.0, 0.3, wand_start=np.zeros(3), robot_start=np.zeros(3))
    workspace.engage([0.02, 0.0, 0.0])
    np.testing.assert_array_equal(workspace.to_robot([-0.05, 0.01, 0.0]), [0.02, 0.0, 0.0])
    np.testing.assert_array_equal(workspace.velocity_to_robot([1.0, 0.0, 0.0]), np.zeros(3))
    workspace.release([-0.05, 0.01, 0.0])  # the wand re-centred while clutched
    np.testing.assert_allclose(workspace.to_robot([-0.05, 0.01, 0.0]), [0.02, 0.0, 0.0])
    np.testing.assert_allclose(workspace.to_robot([-0.04, 0.01, 0.0]), [0.03, 0.0, 0.0])


def test_direct_reflects_the_scaled_force_until_the_link_falls_silent():
    leader = Leader(LeaderConfig('direct', force_scale=0.3, link_timeout=0.1), np.zeros(3),
                    np.zeros(3))
    assert not leader.live(0.0)
    np.testing.assert_array_equal(leader.force(0.0, np.zeros(3), np.zeros(3), 1e-3), np.zeros(3))
    leader.receive(1.0, feedback(50.0))
    np.testing.assert_allclose(leader.force(1.05, np.zeros(3), np.zeros(3), 1e-3), [0.0, 0.0, 1.5])
    np.testing.assert_array_equal(leader.force(1.101, np.zeros(3), np.zeros(3), 1e-3), np.zeros(3))


def test_an_older_or_repeated_feedback_is_ignored():
    leader = Leader(LeaderConfig('direct'), np.zeros(3), np.zeros(3))
    assert leader.receive(1.0, feedback(50.0, (0.0, 0.0, 5.0)))
    assert not leader.receive(1.001, feedback(49.9, (0.0, 0.0, 9.0)))
    assert not leader.receive(1.002, feedback(50.0, (0.0, 0.0, 9.0)))
    np.testing.assert_allclose(leader.force(1.003, np.zeros(3), np.zeros(3), 1e-3),
                               [0.0, 0.0, 1.5])


def test_the_round_trip_comes_from_echoed_stamps_whatever_the_far_clock():
    leader = Leader(LeaderConfig('direct'), np.zeros(3), np.zeros(3))
    far = 1000.0  # the remote clock's offset from ours
    sent, one_way, hold = 5.0, 0.05, 0.003  # a command left at 5.0 s, ours
    replied = sent + one_way + hold + far
    leader.receive(sent + 2 * one_way + hold, feedback(replied, echo=sent, hold=hold))
    assert leader.round_trip.round_trip == pytest.approx(2 * one_way)
    assert leader.round_trip.offset == pytest.approx(far)


@pytest.mark.parametrize('coupling', [CouplingConfig(), None])
def test_tdpa_never_gives_the_hand_more_energy_than_the_robot_put_in(coupling):
    """With or without the coupling: the wand moves out along the patient's force, where the
    link would deliver 1 mJ a millisecond, and the robot has sent 2 mJ."""
    leader = Leader(LeaderConfig('tdpa', force_scale=1.0, coupling=coupling), np.zeros(3),
                    np.zeros(3))
    leader.receive(0.0, feedback(1.0, (0.0, 0.0, 10.0), energy=0.002))
    velocity, dt, given = np.array([0.0, 0.0, 0.1]), 1e-3, []
    for k in range(90):  # the feedback lasts the leader's link timeout
        force = leader.force(0.001 * k, k * dt * velocity, velocity, dt)
        given.append(float(force @ velocity) * dt)  # the force is held over the tick
    assert sum(given) <= 0.002 + 1e-12
    assert max(np.cumsum(given)) <= 0.002 + 1e-12
    assert max(np.cumsum(given)) > 0.0005  # it does pass the robot's energy on


def test_the_model_is_the_remote_plane_in_the_wands_frame_with_felt_gains():
    leader = Leader(LeaderConfig('model', force_scale=0.3, position_scale=0.5),
                    wand_start=[0.1, 0.0, 0.0], robot_start=[0.0, 0.0, 0.0])
    above = np.array([0.1, 0.0, 0.0])
    assert leader.plane(0.0, above) is None
    plane = RemotePlane(np.array([0.0, 0.0, -0.02]), UP, 500.0, 4.0)
    leader.receive(0.0, feedback(1.0, plane=plane))
    local = leader.plane(0.01, above)
    np.testing.assert_allclose(local.point, [0.1, 0.0, -0.04])
    np.testing.assert_array_equal(local.normal, UP)
    assert (local.stiffness, local.damping) == pytest.approx((0.3 * 0.5 * 500.0,
                                                              0.3 * 0.5 * 4.0))
    assert leader.plane(0.2, above) is None  # the link fell silent: nothing to render


def stored(plane, wand):
    return 0.5 * plane.stiffness * max(float((plane.point - wand) @ plane.normal), 0.0) ** 2


def test_a_model_that_arrives_with_the_wand_inside_is_shown_moved_out_and_so_is_the_robot():
    leader = Leader(LeaderConfig('model', force_scale=1.0, position_scale=0.5), np.zeros(3),
                    np.zeros(3))
    wand = np.array([0.0, 0.0, -0.03])  # 30 mm below the start: 15 mm at the robot
    surface = RemotePlane(np.array([0.0, 0.0, -0.01]), UP, 400.0, 0.0)  # 10 mm at the robot
    leader.receive(0.0, feedback(1.0, plane=surface))
    shown = leader.plane(0.001, wand)
    assert stored(shown, wand) == pytest.approx(0.0, abs=1e-15)  # no energy out of nowhere
    assert shown.point[2] == pytest.approx(-0.03)
    np.testing.assert_allclose(leader.command(2.0, wand, np.zeros(3)).position,
                               [0.0, 0.0, -0.015 + 0.5 * 0.01])


def test_energy_an_update_takes_out_pays_for_a_later_one_and_never_more():
    leader = Leader(LeaderConfig('model', force_scale=1.0), np.zeros(3), np.zeros(3))
    wand = np.array([0.0, 0.0, -0.02])
    plane_at = lambda z: RemotePlane(np.array([0.0, 0.0, z]), UP, 400.0, 0.0)  # noqa: E731
    leader.receive(0.0, feedback(1.0, plane=plane_at(0.0)))
    leader.plane(0.001, np.zeros(3))  # shown before the wand went in
    assert stored(leader.plane(0.002, wand), wand) == pytest.approx(0.5 * 400.0 * 0.02 ** 2)
    leader.receive(0.003, feedback(1.1, plane=plane_at(-0.01)))  # the estimate moves in
    assert stored(leader.plane(0.004, wand), wand) == pytest.approx(0.5 * 400.0 * 0.01 ** 2)
    leader.receive(0.005, feedback(1.2, plane=plane_at(0.005)))  # and out past where it was
    back = leader.plane(0.006, wand)
    assert stored(back, wand) == pytest.approx(0.5 * 400.0 * 0.02 ** 2)  # what it took out
    assert back.point[2] == pytest.approx(0.0)  # shown 5 mm in from the estimate


def test_the_follower_holds_until_the_first_command_then_follows_within_the_force_bound():
    end = follower('direct', max_patient_force=20.0, force_margin=1.0)
    tcp = np.zeros(3)
    np.testing.assert_array_equal(end.target(0.0, tcp, np.zeros(3), np.zeros(3), 1e-3), tcp)
    end.receive(0.001, Command(7.0, np.array([0.0, 0.0, -0.005]), np.zeros(3), 0.0))
    np.testing.assert_allclose(end.target(0.002, tcp, np.zeros(3), np.zeros(3), 1e-3),
                               [0.0, 0.0, -0.005])
    end.receive(0.003, Command(7.001, np.array([0.0, 0.0, -0.3]), np.zeros(3), 0.0))
    deep = end.target(0.004, tcp, np.zeros(3), np.zeros(3), 1e-3)
    assert np.linalg.norm(deep - tcp) == pytest.approx(19.0 / 1500.0)
    assert not end.receive(0.005, Command(7.0005, np.zeros(3), np.zeros(3), 0.0))


def test_a_nan_reading_feeds_back_no_force_and_no_plane_and_the_echo_holds():
    end = follower('direct')
    end.receive(1.0, Command(42.0, np.zeros(3), np.zeros(3), 0.0))
    end.target(1.001, np.zeros(3), np.zeros(3), np.array([0.0, 0.0, 4.0]), 1e-3)
    assert end.feedback(1.002).force[2] == 4.0
    end.target(1.003, np.zeros(3), np.zeros(3), np.array([np.nan, 0.0, 4.0]), 1e-3)
    sent = end.feedback(1.004)
    np.testing.assert_array_equal(sent.force, np.zeros(3))
    assert sent.plane is None
    assert (sent.echo, sent.echo_hold) == pytest.approx((42.0, 0.004))


def test_the_plane_sent_has_the_tissue_in_series_with_the_robots_spring():
    linear = HuntCrossley(stiffness=700.0, exponent=1.0, damping=0.0)
    robot = ImpedanceRobot(ImpedanceRobotConfig(stiffness=1500.0),
                           environment=Tissue(linear, PlaneSurface([0.0, 0.0, -0.01], UP)))
    end = follower('model')
    end.receive(0.0, Command(1.0, np.zeros(3), np.zeros(3), 0.0))
    state, now = robot.read(0.0), 0.0
    for k in range(3000):  # press 1 cm to 2.5 cm below the skin and back, slowly
        now = 1e-3 * (k + 1)
        depth = 0.01 + 0.015 * np.sin(np.pi * now / 3.0)
        end.receive(now, Command(1.0 + now, np.array([0.0, 0.0, -0.01 - depth]), np.zeros(3),
                                 0.0))
        robot.command(end.target(now, state.position, state.velocity, state.external_force,
                                 1e-3))
        state = robot.read(now)
    plane = end.feedback(now).plane
    assert plane.stiffness == pytest.approx(700.0 * 1500.0 / 2200.0, rel=0.02)
    assert plane.point[2] == pytest.approx(-0.01, abs=2e-4)
    np.testing.assert_allclose(plane.normal, UP, atol=1e-3)
