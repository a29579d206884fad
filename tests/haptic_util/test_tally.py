"""Counting repeated events: one line a period for what is new, none when nothing is."""
from haptic_util.tally import Tally


def test_new_events_are_logged_once_with_their_latest_detail():
    tally = Tally()
    lines = []
    tally.log_new(lines.append)
    assert lines == []
    for stamp in (1, 2, 3):
        tally.add('stale input', f'stamp {stamp}')
    tally.add('wrong frame')
    tally.log_new(lines.append)
    assert lines == ['3 x stale input (latest: stamp 3); 1 x wrong frame']
    tally.log_new(lines.append)
    assert len(lines) == 1  # nothing new
    tally.add('wrong frame')
    tally.log_new(lines.append)
    assert lines[-1] == '1 x wrong frame'
    assert tally.counts == {'stale input': 3, 'wrong frame': 2} and tally.total() == 5
