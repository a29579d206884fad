"""Admission at one end of the link: one session, in order, on time, at a sane rate."""
import math

import pytest

from teleop_protocol.admission import Admission, AdmissionConfig

SESSION, OTHER = 0xA11CE, 0xB0B
OFFSET, DELAY = 1000.0, 0.05  # [s] their clock minus ours, and the link's one-way delay


def stream(admission, start, count, *, period=1e-3, first=1, delay=DELAY, session=SESSION):
    """Send ``count`` messages from ``start`` (s, our clock), return the refusals' kinds."""
    kinds = []
    for k in range(count):
        sent = start + k * period
        refusal = admission.admit(sent + delay, session, first + k, sent + OFFSET)
        kinds.append(None if refusal is None else refusal.kind)
    return kinds


def test_the_first_session_heard_is_followed_and_another_is_refused_and_named():
    admission = Admission()
    assert stream(admission, 0.0, 100) == [None] * 100
    refusal = admission.admit(0.2, OTHER, 1_000_000, 0.2 + OFFSET)
    assert refusal.kind == 'another session' and '0xb0b' in refusal.detail
    assert admission.session == SESSION


def test_another_session_takes_over_once_the_followed_one_is_silent():
    admission = Admission(AdmissionConfig(session_timeout=1.0))
    stream(admission, 0.0, 10)
    assert admission.admit(0.5, OTHER, 1, 0.5 + OFFSET).kind == 'another session'
    assert admission.admit(1.2, OTHER, 1, 1.2 + OFFSET) is None
    assert admission.session == OTHER


def test_a_repeat_or_an_older_message_is_not_taken():
    admission = Admission()
    stream(admission, 0.0, 10)
    assert admission.admit(0.1, SESSION, 10, 0.1 + OFFSET).kind == \
        'not newer than the last taken'  # a newer stamp, an old sequence
    assert admission.admit(0.1, SESSION, 11, 0.001 + OFFSET).kind == \
        'not newer than the last taken'  # a newer sequence, an old stamp
    assert admission.admit(0.1, SESSION, 0, 0.1 + OFFSET).kind == \
        'not newer than the last taken'


def test_a_sequence_number_far_ahead_of_its_stamp_is_refused_and_moves_nothing():
    admission = Admission()
    stream(admission, 0.0, 100)
    assert admission.admit(0.15, SESSION, 2**63, 0.1 + OFFSET).kind == \
        'sequence ahead of its stamp'
    assert stream(admission, 0.1, 10, first=101) == [None] * 10


@pytest.mark.parametrize('session', [0])
def test_a_message_of_no_session_is_refused(session):
    assert Admission().admit(0.0, session, 1, 0.0).kind == 'no session'


def test_a_stamp_from_the_future_is_refused_and_moves_nothing():
    """A forged stamp 10 s ahead, taken, made every true command after it look old."""
    admission = Admission()
    stream(admission, 0.0, 500)
    forged = admission.admit(0.5 + DELAY, SESSION, 10_000, 10.5 + OFFSET)
    assert forged.kind == 'stamped in the future' and '10.5' in forged.detail
    assert stream(admission, 0.5, 500, first=501) == [None] * 500


def test_a_few_forged_stamps_do_not_move_the_baseline():
    """Stamps a little ahead, each under the lead allowed, each a step further: had the
    baseline been the least lateness, each would have moved it, and the next one further."""
    admission = Admission()
    stream(admission, 0.0, 5000)
    for k in range(40):  # 0.8 % of the history, under the 1 % quantile
        lead = 0.04 * (k + 1)
        refusal = admission.admit(5.0 + k * 1e-3 + DELAY, SESSION, 5001 + k,
                                  5.0 + k * 1e-3 + lead + OFFSET)
        assert k == 0 or refusal.kind == 'stamped in the future'
    assert admission.admit(5.05 + DELAY, SESSION, 5100, 5.05 + 0.06 + OFFSET).kind == \
        'stamped in the future'  # 60 ms ahead of the true link still is


def test_after_a_stall_the_queued_commands_are_dropped_and_the_fresh_ones_taken():
    """The link stalls for 0.5 s, then delivers what it held at once: 593 ms old at most."""
    admission = Admission()
    stream(admission, 0.0, 1000)
    kinds = []
    for k in range(600):  # sent 1.0 to 1.6 s, all arriving at 1.65 s
        sent = 1.0 + k * 1e-3
        refusal = admission.admit(1.6 + DELAY, SESSION, 1001 + k, sent + OFFSET)
        kinds.append(None if refusal is None else refusal.kind)
    late = [kind for kind in kinds[:-101] if kind != 'older than the link allows']
    assert late == [], 'a command more than 0.1 s old was executed'
    assert kinds[-99:] == [None] * 99  # the last 0.1 s is taken, as the rate allows


def test_while_messages_flow_a_late_one_is_still_taken():
    """A busy machine delays them all: the newest there is beats holding the robot."""
    admission = Admission()
    stream(admission, 0.0, 500)
    kinds = [admission.admit(0.5 + k * 1e-3 + DELAY + k * 1e-3, SESSION, 501 + k,
                             0.5 + k * 1e-3 + OFFSET) for k in range(300)]  # 0.3 s later
    assert kinds == [None] * 300


def test_a_stall_longer_than_the_history_is_still_judged_against_what_came_before():
    admission = Admission()
    stream(admission, 0.0, 600)
    old = admission.admit(30.0 + DELAY, SESSION, 601, 29.0 + OFFSET)  # a second late
    assert old.kind == 'older than the link allows'


def test_a_slower_link_or_a_stepped_clock_is_learnt_again_after_a_second_of_refusals():
    for step in (0.2, -0.2):  # the link 0.2 s slower; their clock 0.2 s ahead
        admission = Admission(AdmissionConfig(relearn=1.0))
        stream(admission, 0.0, 500)
        kinds = stream(admission, 1.0, 2000, first=501, delay=DELAY + step)
        assert set(kinds[:1000]) == {'older than the link allows' if step > 0 else
                                     'stamped in the future'}
        assert kinds[1001:] == [None] * 999


def test_a_flood_from_the_session_itself_is_shed_at_the_rate():
    admission = Admission(AdmissionConfig(max_rate=2000.0, burst=0.05))
    kinds = stream(admission, 0.0, 20_000, period=1 / 20_000)  # 1 s at 20 kHz
    taken = kinds.count(None)
    assert kinds.count("over the session's rate") == 20_000 - taken
    assert 2000 <= taken <= 2000 + 2000 * 0.05 + 1


@pytest.mark.parametrize('fields, message', [
    (dict(max_age=0.0), 'max_age must be finite > 0'),
    (dict(max_lead=math.nan), 'max_lead must be finite > 0'),
    (dict(history=0), 'history must be an integer >= 1'),
    (dict(quantile=1.5), 'quantile must be finite >= 0 <= 1'),
    (dict(relearn=-1.0), 'relearn must be finite > 0'),
])
def test_bad_configurations_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        AdmissionConfig(**fields)
