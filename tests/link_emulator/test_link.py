"""The emulated link's delay statistics on seeded runs."""
import math

import numpy as np
import pytest

from link_emulator.link import DelayTrace, EmulatedLink, LinkConfig

PERIOD = 1e-3  # s between messages, as the 1 kHz topics that cross


def run(config, count=20000, trace=None):
    """Send ``count`` messages (their index) one PERIOD apart; return every delivery."""
    link = EmulatedLink(config, trace=trace)
    deliveries = []
    for index in range(count):
        link.send(index * PERIOD, index)
        deliveries += link.deliver(index * PERIOD)
    return link, deliveries + link.deliver(math.inf)


def test_delays_and_losses_have_the_configured_statistics():
    count = 20000
    link, deliveries = run(LinkConfig(delay=0.05, jitter=0.005, loss=0.01, reorder=True,
                                      seed=11), count)
    delays = np.array([d.arrived - d.sent for d in deliveries])
    # Mean within 4 standard errors, standard deviation within 4 % (its standard error: 0.5 %).
    assert abs(delays.mean() - 0.05) < 4 * 0.005 / math.sqrt(delays.size)
    assert delays.std() == pytest.approx(0.005, rel=0.04)
    # Losses within 4 standard deviations of the binomial.
    assert abs(link.lost / count - 0.01) < 4 * math.sqrt(0.01 * 0.99 / count)
    assert len(deliveries) == link.sent - link.lost == count - link.lost


def test_without_reordering_no_message_overtakes_and_with_it_some_do():
    config = dict(delay=0.02, jitter=0.005, seed=2)
    _, ordered = run(LinkConfig(**config), 5000)
    _, reordered = run(LinkConfig(reorder=True, **config), 5000)
    assert [d.payload for d in ordered] == sorted(d.payload for d in ordered)
    overtaken = np.sum(np.diff([d.payload for d in reordered]) < 0)
    assert overtaken > 100  # jitter (5 ms) well over the period (1 ms)
    # Held back behind late ones, an ordered message arrives no earlier than its own delay.
    assert np.mean([d.arrived - d.sent for d in ordered]) > 0.02


def test_a_message_is_delivered_once_and_only_when_it_is_due():
    link = EmulatedLink(LinkConfig(delay=0.05))
    link.send(1.0, 'a')
    link.send(1.01, 'b')
    assert link.deliver(1.0499) == []
    assert link.next_arrival == pytest.approx(1.05)
    assert [d.payload for d in link.deliver(1.055)] == ['a']
    assert [d.payload for d in link.deliver(2.0)] == ['b']
    assert link.deliver(3.0) == [] and link.next_arrival is None


def test_jitter_never_makes_a_delay_negative():
    _, deliveries = run(LinkConfig(delay=0.001, jitter=0.01, reorder=True, seed=5), 2000)
    delays = np.array([d.arrived - d.sent for d in deliveries])
    assert delays.min() == 0.0 and np.mean(delays == 0.0) > 0.3


def test_a_seed_gives_the_same_run():
    config = LinkConfig(delay=0.03, jitter=0.004, loss=0.05, reorder=True, seed=9)
    assert run(config, 3000)[1] == run(config, 3000)[1]


def test_a_delay_trace_is_replayed_from_csv(tmp_path):
    path = tmp_path / 'trace.csv'
    path.write_text('time,delay\n0.0,0.010\n1.0,0.100\n2.0,0.050\n')
    trace = DelayTrace.from_csv(path)
    link = EmulatedLink(trace=trace)
    for time, payload in [(5.0, 'start'), (5.5, 'a'), (6.5, 'b'), (8.0, 'c')]:
        link.send(time, payload)
    delays = {d.payload: d.arrived - d.sent for d in link.deliver(math.inf)}
    assert delays == pytest.approx({'start': 0.01, 'a': 0.01, 'b': 0.1, 'c': 0.05})


def test_a_trace_after_a_time_is_what_a_run_begun_then_replays(tmp_path):
    trace = DelayTrace([0.0, 1.0, 2.0, 3.0], [0.01, 0.1, 0.05, 0.2])
    later = trace.after(1.5)
    assert later.times.tolist() == [0.0, 0.5, 1.5]
    assert [later.delay_at(t) for t in (0.0, 0.4, 0.5, 9.0)] == [0.1, 0.1, 0.05, 0.2]
    assert trace.after(2.0).times.tolist() == [0.0, 1.0]
    assert trace.after(0.5, length=1.5).delays.tolist() == [0.01, 0.1]
    path = tmp_path / 'later.csv'
    later.to_csv(path)
    again = DelayTrace.from_csv(path)
    assert again.times.tolist() == later.times.tolist()
    assert again.delays.tolist() == later.delays.tolist()
    with pytest.raises(ValueError, match='past the last sample'):
        trace.after(3.5)
    with pytest.raises(ValueError, match='start must be finite >= 0'):
        trace.after(-1.0)
    with pytest.raises(ValueError, match='length must be > 0 s'):
        trace.after(1.0, length=0.0)


@pytest.mark.parametrize('text, message', [
    ('t,d\n0,0.1\n', 'header "time,delay"'),
    ('time,delay\n0,abc\n', 'two numbers'),
    ('time,delay\n0,0.1,3\n', 'two numbers'),
    ('time,delay\n0,0.1\n0,0.2\n', 'increase strictly'),
    ('time,delay\n0,-0.1\n', 'delays be >= 0'),
    ('time,delay\n0,nan\n', 'must be finite'),
    ('time,delay\n', 'at least one'),
])
def test_bad_traces_are_refused(tmp_path, text, message):
    path = tmp_path / 'trace.csv'
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        DelayTrace.from_csv(path)


@pytest.mark.parametrize('fields, message', [
    (dict(delay=-0.01), 'delay must be finite >= 0'),
    (dict(jitter=math.nan), 'jitter must be finite >= 0'),
    (dict(loss=1.0), r'loss must be in \[0, 1\)'),
    (dict(reorder='yes'), 'reorder must be true or false'),
    (dict(seed=-3), 'seed must be an integer >= 0'),
])
def test_bad_configurations_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        LinkConfig(**fields)


def test_sending_back_in_time_is_refused():
    link = EmulatedLink()
    link.send(1.0, None)
    with pytest.raises(ValueError, match='must not go back'):
        link.send(0.5, None)


def test_a_reliable_message_is_never_lost_and_each_loss_costs_it_a_round_trip():
    count = 2000
    link = EmulatedLink(LinkConfig(delay=0.05, loss=0.5, reorder=True, seed=4))
    assert all(link.send(index * PERIOD, index, reliable=True) for index in range(count))
    deliveries = link.deliver(math.inf)
    assert sorted(d.payload for d in deliveries) == list(range(count)) and link.lost == 0
    late = np.array([(d.arrived - d.sent - 0.05) / 0.1 for d in deliveries])
    round_trips = np.round(late)
    np.testing.assert_allclose(late, round_trips, atol=1e-9)
    assert round_trips.sum() == link.retransmitted
    # First time through for half of them, within 4 standard deviations of the binomial.
    assert abs(np.mean(round_trips == 0) - 0.5) < 4 * math.sqrt(0.25 / count)
