"""The measured intercontinental link: the published file, replayed as its README says."""

import csv
import subprocess

from bench.measured_link import echo_delays, ECHO_ROUND_TRIPS
import pytest

PUBLISHED_BLOB = '0eda2b72a4cc52a38940307440012e2d6783d586'  # at the source's commit 31a5eb2


def test_the_shipped_round_trips_are_the_published_file_unmodified():
    blob = subprocess.run(['git', 'hash-object', str(ECHO_ROUND_TRIPS)], capture_output=True,
                          text=True, check=True).stdout.strip()
    assert blob == PUBLISHED_BLOB


def test_each_way_is_half_a_round_trip_sent_when_the_last_came_back():
    with ECHO_ROUND_TRIPS.open(newline='') as file:
        round_trips_ms = [int(row[0]) for row in csv.reader(file)]
    trace = echo_delays()
    assert len(trace.times) == len(round_trips_ms) == 1000
    sent = 0.0
    for k, round_trip in enumerate(round_trips_ms):
        assert trace.times[k] == pytest.approx(sent, abs=1e-9)
        assert trace.delays[k] == pytest.approx(round_trip / 2e3)
        sent += round_trip / 1e3
    assert max(round_trips_ms) == 2307 and trace.delays.max() == pytest.approx(1.1535)


@pytest.mark.parametrize('text, message', [('305\nabc\n', 'one round trip in ms'),
                                           ('305\n0\n', 'finite and > 0 ms')])
def test_a_bad_round_trip_file_is_refused(tmp_path, text, message):
    path = tmp_path / 'echo.csv'
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        echo_delays(path)
