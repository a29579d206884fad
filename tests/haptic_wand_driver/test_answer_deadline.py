"""When an answer stops being rendered: its lifetime, or longer while the next pose is late."""
import math

import pytest

from haptic_wand_driver.answer_deadline import AnswerDeadline

LIFETIME = 0.010  # [s]


def answered(hold: float) -> AnswerDeadline:
    """A driver that sent a pose at 1 s and holds its answer."""
    answers = AnswerDeadline(hold)
    answers.sent(1.000, 1.000)
    answers.taken(1.000, LIFETIME)
    return answers


def test_without_a_hold_an_answer_lives_its_lifetime_whatever_the_ticks_do():
    answers = answered(hold=0.0)
    assert answers.deadline == 1.010
    assert not answers.sent(1.050, 1.050)  # a late tick: the deadline stays where it was
    assert answers.deadline == 1.010
    assert answers.late == 1


def test_the_answer_to_the_newest_pose_holds_until_the_next_is_sent_at_most_the_hold():
    answers = answered(hold=0.1)
    assert answers.deadline == pytest.approx(1.1)  # no newer pose yet: as long as the hold
    assert answers.sent(1.035, 1.035)  # the next pose, 35 ms late: the answer held until then
    assert answers.deadline == 1.035
    assert not answers.sent(1.036, 1.036)  # only the first pose after it counts
    assert answers.deadline == 1.035
    assert answers.late == 1


def test_a_tick_that_stalls_before_its_pose_goes_out_holds_the_answer_until_it_does():
    answers = answered(hold=0.1)
    assert answers.sent(1.001, 1.040)  # stamped on time, sent 39 ms later
    assert answers.deadline == 1.040
    assert answers.late == 1


def test_a_loop_that_stops_answering_while_the_driver_ticks_still_zeroes_at_the_lifetime():
    answers = answered(hold=0.1)
    for k in range(1, 30):  # on time, and no answer comes to any of them
        answers.sent(1.0 + k * 0.001, 1.0 + k * 0.001)
    assert answers.deadline == 1.010
    assert answers.late == 0


def test_an_answer_to_an_older_pose_lives_its_lifetime_only():
    answers = AnswerDeadline(hold=0.1)
    answers.sent(1.000, 1.000)
    answers.sent(1.020, 1.020)
    answers.taken(1.000, LIFETIME)  # arrived after the next pose went out
    assert answers.deadline == 1.010
    assert not answers.sent(1.030, 1.030)


def test_nothing_taken_renders_nothing():
    assert AnswerDeadline(hold=0.1).deadline == -math.inf
