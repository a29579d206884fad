"""Both ends of the bilateral schemes, and the map between the wand and the robot."""
import numpy as np
import pytest

from haptic_contract.teleop import Command, CommandLimits, Feedback, RemotePlane
from robot_site.follower import Follower, FollowerConfig
from robot_site.impedance_robot import ImpedanceRobot, ImpedanceRobotConfig
from robot_site.model_estimation import ContactModelEstimator
from robot_site.safety import PatientSafety, SafetyConfig
from robot_site.tissue import HuntCrossley, PlaneSurface, Tissue
from teleop_leader.leader import Leader, LeaderConfig
from teleop_leader.virtual_coupling import CouplingConfig
from teleop_leader.workspace_map import WorkspaceMap

UP = np.array([0.0, 0.0, 1.0])
REMOTE, OPERATOR = 0x5EED, 0x0BE7  # the two sites' sessions
LIMITS = CommandLimits(np.full(3, -0.4), np.full(3, 0.4), 5.0)


def feedback(stamp, force=(0.0, 0.0, 5.0), *, echo=0.0, hold=0.0, energy=0.0, plane=None,
             echo_sequence=0):
    """A feedback numbered by its stamp, in the milliseconds (so later ones are newer)."""
    return Feedback(stamp, echo, hold, np.array(force), np.zeros(3), energy, plane, REMOTE,
                    round(stamp * 1000) + 1, echo_sequence)


def command(stamp, position=(0.0, 0.0, 0.0)):
    """A command numbered by its stamp, in the milliseconds (so later ones are newer)."""
    return Command(stamp, np.array(position), np.zeros(3), 0.0, OPERATOR,
                   round(stamp * 1000) + 1)


def follower(scheme='direct', **safety):
    config = FollowerConfig(scheme, robot_stiffness=1500.0)
    return Follower(config, PatientSafety(SafetyConfig(robot_stiffness=1500.0, **safety)),
                    LIMITS, ContactModelEstimator())


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
    assert leader.receive(1.0, feedback(50.0, (0.0, 0.0, 5.0))) is None
    assert leader.receive(1.001, feedback(49.9, (0.0, 0.0, 9.0))).kind == \
        'not newer than the last taken'
    assert leader.receive(1.002, feedback(50.0, (0.0, 0.0, 9.0))) is not None
    np.testing.assert_allclose(leader.force(1.003, np.zeros(3), np.zeros(3), 1e-3),
                               [0.0, 0.0, 1.5])


def test_the_round_trip_comes_from_echoed_stamps_whatever_the_far_clock():
    leader = Leader(LeaderConfig('direct'), np.zeros(3), np.zeros(3))
    far = 1000.0  # the remote clock's offset from ours
    sent, one_way, hold = 5.0, 0.05, 0.003  # a command left at 5.0 s, ours
    leader.receive(4.99, feedback(4.94 + far))  # no echo yet: the link is live
    sequence = leader.command(sent, np.zeros(3), np.zeros(3)).sequence
    replied = sent + one_way + hold + far
    assert leader.receive(sent + 2 * one_way + hold, feedback(
        replied, echo=sent, hold=hold, echo_sequence=sequence)) is None
    assert leader.round_trip.round_trip == pytest.approx(2 * one_way)
    assert leader.round_trip.offset == pytest.approx(far)


def test_an_echo_of_a_command_never_sent_here_is_refused_and_measures_nothing():
    """A forged command stamped 10 s ahead, echoed back, made every feedback raise."""
    leader = Leader(LeaderConfig('direct'), np.zeros(3), np.zeros(3))
    leader.receive(1.0, feedback(100.0))
    sequence = leader.command(1.001, np.zeros(3), np.zeros(3)).sequence
    forged = leader.receive(1.1, feedback(100.1, echo=11.0, echo_sequence=sequence + 1))
    assert forged.kind == 'echo of no command sent here' and '11.000000' in forged.detail
    wrong_stamp = leader.receive(1.1, feedback(100.1, echo=11.0, echo_sequence=sequence))
    assert wrong_stamp.kind == 'echo of no command sent here'
    too_long = leader.receive(1.1, feedback(100.1, echo=1.001, hold=0.5,
                                            echo_sequence=sequence))
    assert too_long.kind == 'echo held longer than its round trip'
    assert leader.round_trip.round_trip is None
    assert leader.receive(1.1, feedback(100.1, echo=1.001, hold=0.001,
                                        echo_sequence=sequence)) is None
    assert leader.round_trip.round_trip == pytest.approx(0.098)


def test_no_command_is_sent_while_the_feedback_is_silent():
    """The robot then holds, as when the commands stop, rather than follow a hand that feels
    nothing; the commands come again with the feedback, numbered on."""
    leader = Leader(LeaderConfig('model', link_timeout=0.1), np.zeros(3), np.zeros(3))
    assert leader.command(0.5, np.zeros(3), np.zeros(3)) is None  # nothing heard yet
    leader.receive(1.0, feedback(10.0))
    first = leader.command(1.05, np.zeros(3), np.zeros(3))
    assert first.session == leader.session != 0 and first.sequence == 1
    assert leader.command(1.2, np.zeros(3), np.zeros(3)) is None
    leader.receive(1.3, feedback(10.3))
    assert leader.command(1.31, np.zeros(3), np.zeros(3)).sequence == 2


def test_feedback_of_another_remote_site_or_out_of_range_is_refused():
    leader = Leader(LeaderConfig('direct'), np.zeros(3), np.zeros(3))
    assert leader.receive(1.0, feedback(10.0)) is None
    stranger = feedback(10.1)._replace(session=REMOTE + 1)
    assert leader.receive(1.1, stranger).kind == 'another session'
    assert leader.receive(1.1, feedback(10.1, energy=-1.0)).kind == 'negative energy'
    assert leader.receive(1.1, feedback(10.1, (0.0, 0.0, 1e9))).kind == \
        'force beyond any sensor'
    tilted = RemotePlane(np.zeros(3), np.array([0.0, 0.0, 2.0]), 500.0, 4.0)
    assert leader.receive(1.1, feedback(10.1, plane=tilted)).kind == 'plane normal not unit'
    np.testing.assert_allclose(leader.force(1.05, np.zeros(3), np.zeros(3), 1e-3),
                               [0.0, 0.0, 1.5])  # still the first one's force


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
    np.testing.assert_allclose(leader.command(0.002, wand, np.zeros(3)).position,
                               [0.0, 0.0, -0.015 + 0.5 * 0.01])


def test_energy_an_update_takes_out_pays_for_a_later_one_and_never_more():
    leader = Leader(LeaderConfig('model', force_scale=1.0), np.zeros(3), np.zeros(3))
    wand = np.array([0.0, 0.0, -0.02])
    plane_at = lambda z: RemotePlane(np.array([0.0, 0.0, z]), UP, 400.0, 0.0)  # noqa: E731
    leader.receive(0.0, feedback(1.0, plane=plane_at(0.0)))
    leader.plane(0.001, np.zeros(3))  # shown before the wand went in
    assert stored(leader.plane(0.002, wand), wand) == pytest.approx(0.5 * 400.0 * 0.02 ** 2)
    leader.receive(0.003, feedback(1.003, plane=plane_at(-0.01)))  # the estimate moves in
    assert stored(leader.plane(0.004, wand), wand) == pytest.approx(0.5 * 400.0 * 0.01 ** 2)
    leader.receive(0.005, feedback(1.005, plane=plane_at(0.005)))  # and out past where it was
    back = leader.plane(0.006, wand)
    assert stored(back, wand) == pytest.approx(0.5 * 400.0 * 0.02 ** 2)  # what it took out
    assert back.point[2] == pytest.approx(0.0)  # shown 5 mm in from the estimate


def test_the_follower_holds_until_the_first_command_then_follows_within_the_force_bound():
    end = follower('direct', max_patient_force=20.0, force_margin=1.0)
    tcp = np.zeros(3)
    np.testing.assert_array_equal(end.target(0.0, tcp, np.zeros(3), np.zeros(3), 1e-3), tcp)
    end.receive(0.001, command(7.0, [0.0, 0.0, -0.005]))
    np.testing.assert_allclose(end.target(0.002, tcp, np.zeros(3), np.zeros(3), 1e-3),
                               [0.0, 0.0, -0.005])
    end.receive(0.003, command(7.001, [0.0, 0.0, -0.3]))
    deep = end.target(0.004, tcp, np.zeros(3), np.zeros(3), 1e-3)
    assert np.linalg.norm(deep - tcp) == pytest.approx(19.0 / 1500.0)
    assert end.receive(0.005, command(7.0005)).kind == 'not newer than the last taken'


def test_a_nan_reading_feeds_back_no_force_and_no_plane_and_the_echo_holds():
    end = follower('direct')
    end.receive(1.0, command(42.0))
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
    end.receive(0.0, command(1.0))
    state, now = robot.read(0.0), 0.0
    for k in range(3000):  # press 1 cm to 2.5 cm below the skin and back, slowly
        now = 1e-3 * (k + 1)
        depth = 0.01 + 0.015 * np.sin(np.pi * now / 3.0)
        end.receive(now, command(1.0 + now, [0.0, 0.0, -0.01 - depth]))
        robot.command(end.target(now, state.position, state.velocity, state.external_force,
                                 1e-3))
        state = robot.read(now)
    plane = end.feedback(now).plane
    assert plane.stiffness == pytest.approx(700.0 * 1500.0 / 2200.0, rel=0.02)
    assert plane.point[2] == pytest.approx(-0.01, abs=2e-4)
    np.testing.assert_allclose(plane.normal, UP, atol=1e-3)


def pressed_into_the_skin():
    """A model leader, unscaled, shown the skin 10 mm under the start, the wand 10 mm into it.

    Returns the leader, the skin, the wand and the energy the shown spring holds there (J).
    """
    leader = Leader(LeaderConfig('model', force_scale=1.0, position_scale=1.0), np.zeros(3),
                    np.zeros(3))
    skin = RemotePlane(np.array([0.0, 0.0, -0.01]), UP, 400.0, 0.0)
    leader.receive(0.0, feedback(1.0, plane=skin))
    assert leader.plane(0.001, np.array([0.0, 0.0, -0.01])) is not None  # at the skin
    pressed = np.array([0.0, 0.0, -0.02])
    return leader, skin, pressed, stored(leader.plane(0.002, pressed), pressed)


def test_a_silence_keeps_the_books_the_hand_feels_what_it_left_and_the_robot_presses_as_much():
    """Pressed 10 mm into the shown plane, the link fell silent and the hand sank 30 mm more.
    The first model after it stores what the spring held when the silence began, no more (no
    jolt, passive), and the robot's target, moved out by the same shift, presses the patient
    with the force the hand feels."""
    leader, skin, pressed, before = pressed_into_the_skin()
    assert before == pytest.approx(0.5 * 400.0 * 0.01 ** 2)
    assert leader.model(0.5, pressed) == (False, None)  # silent: unknown, no model
    deep = np.array([0.0, 0.0, -0.05])
    leader.receive(1.0, feedback(2.0, plane=skin))
    again = leader.plane(1.0, deep)
    assert stored(again, deep) == pytest.approx(before)
    felt = again.stiffness * (again.point[2] - deep[2])
    target = leader.command(1.0, deep, np.zeros(3)).position
    patient = skin.stiffness * (skin.point[2] - target[2])
    assert felt == pytest.approx(patient) == pytest.approx(4.0)


def test_feedback_with_no_good_reading_is_a_silence_not_a_free_contact():
    """Pressed 10 mm in, the robot's sensor reads nothing good for a while (a starved remote
    site) and the hand sinks 30 mm. Meanwhile: no force, no command, no model. Then the first
    plane stores what the spring held before, as after a silence; a free estimate would have
    closed the books and shown it 40 mm out (ci18: the patient let go after a flood)."""
    leader, skin, pressed, before = pressed_into_the_skin()
    unread = feedback(1.003, (0.0, 0.0, 0.0))._replace(measured=False)
    assert leader.receive(0.003, unread) is None and leader.live(0.004)
    assert leader.model(0.004, pressed) == (False, None)
    assert leader.command(0.004, pressed, np.zeros(3)) is None
    np.testing.assert_array_equal(leader.force(0.004, pressed, np.zeros(3), 1e-3), np.zeros(3))
    deep = np.array([0.0, 0.0, -0.05])
    leader.receive(0.005, feedback(1.005, plane=skin))
    assert stored(leader.plane(0.006, deep), deep) == pytest.approx(before)


def test_the_clutch_closes_the_books_as_the_device_does_for_a_free_model():
    """Pressed 10 mm in, the operator clutches (the device renders free and closes its books),
    moves the wand 30 mm deeper and lets go: nothing is stored at first, on either side."""
    leader, _, pressed, before = pressed_into_the_skin()
    assert before > 0.0
    leader.map.engage(pressed)
    assert leader.model(0.003, pressed) == (True, None)  # known: free
    deep = np.array([0.0, 0.0, -0.05])
    leader.map.release(deep)
    assert stored(leader.plane(0.004, deep), deep) == pytest.approx(0.0, abs=1e-15)


def test_a_command_of_another_session_or_out_of_the_robots_reach_is_refused_and_changes_nothing():
    end = follower('tdpa')
    assert end.receive(0.0, command(1.0, [0.0, 0.0, -0.01])) is None
    stranger = command(1.001, [0.0, 0.0, -0.3])._replace(session=OPERATOR + 1)
    assert end.receive(0.001, stranger).kind == 'another session'
    assert end.receive(0.002, command(1.002, [0.0, 0.0, -0.5])).kind == 'outside the workspace'
    absurd = command(1.003)._replace(velocity=np.array([-1.7e308, 0.0, 0.0]))
    assert end.receive(0.003, absurd).kind == 'faster than a hand'
    assert end.receive(0.004, command(1.004)._replace(energy_in=-1.0)).kind == \
        'negative energy'
    nan = command(1.005)._replace(position=np.array([0.0, np.nan, 0.0]))
    assert end.receive(0.005, nan).kind == 'not finite'
    target = end.target(0.006, np.zeros(3), np.zeros(3), np.zeros(3), 1e-3)
    np.testing.assert_allclose(target, [0.0, 0.0, -1e-3 * 0.0], atol=0.011)
    sent = end.feedback(0.007)
    assert np.isfinite(sent.energy_in) and sent.echo == 1.0 and sent.echo_sequence == \
        command(1.0).sequence
