"""The report's probe images: which frames it shows, and how it states the image's figures."""
from bench.imaging_session import label
import numpy as np
from report_generator.report_image import (ALONG, cost_section, ImageScan, pressure_frames,
                                           scan_frames, scan_section, variants_section)

from haptic_bringup.session import Frames

RATE = 30.0  # [Hz]


def scan(force) -> ImageScan:
    """A scan whose n frames come at 30 Hz, 60 ms late, with the patient force ``force``."""
    force = np.asarray(force, dtype=float)
    stamp = 100.0 + np.arange(len(force)) / RATE
    images = np.zeros((len(force), 4, 6), dtype=np.uint8)
    frames = Frames(stamp + 0.06, stamp, images, {'ultrasound_probe'})
    return ImageScan(frames, stamp - stamp[0], force, np.zeros((len(force), 3)),
                     np.full(len(force), 0.06))


def test_frames_along_the_scan_span_the_contact_and_the_strip_the_first_press():
    # In air for 1 s, pressing up to 8 N over 1 s, held 2 s, let go, and pressed again.
    force = np.r_[np.zeros(30), np.linspace(0.0, 8.0, 30), np.full(60, 8.0), np.zeros(30),
                  np.full(30, 9.0)]
    shown = scan(force)
    along = scan_frames(shown)
    assert len(along) == ALONG
    assert shown.force[along[0]] > 1.0 and along[-1] == len(force) - 1
    strip = pressure_frames(shown)
    assert list(strip) == [0.0, 0.5, 2.0, 4.0, 6.0, 8.0]
    assert shown.force[strip[0.0]] == 0.0 and shown.time[strip[0.0]] < 1.0 - 0.2
    for pressure, index in list(strip.items())[1:]:
        assert shown.force[index] >= pressure > shown.force[index - 1]
    assert scan_frames(scan(np.zeros(10))).size == 0 and pressure_frames(scan(np.zeros(10))) == {}


def test_the_scan_section_states_rate_and_lateness_against_the_target():
    text = scan_section(scan(np.r_[np.zeros(10), np.full(30, 5.0)]), 0.05)
    assert '40 frames of 6 x 4 mono8 in `ultrasound_probe`, 30.0 a second' in text
    assert '75% of them with the probe on the patient' in text
    assert 'p50 60 ms, p99 60 ms, over a link of 50 ms one way (target: p99 <= 100 ms)' in text


def test_the_cost_section_says_which_target_each_ratio_meets():
    def row(imaging, rate, p99):
        return {'imaging': imaging, 'variant': 'idle' if imaging else 'off', 'load': 3.0,
                'thread_priority': 50,
                'operator_rate_hz': rate,
                'operator_answered_percent': 100.0, 'operator_round_trip_p99_s': p99,
                'robot_rate_hz': 1000.0, 'robot_tick_p99_s': 0.002, 'commands_hz': 1000.0,
                'feedback_hz': 100.0}
    rows = [row(True, 980.0, 0.0012), row(False, 1000.0, 0.001)]
    keys = [k for k in rows[0] if k not in ('imaging', 'variant', 'load', 'thread_priority')]
    ratios = {k: rows[0][k] / rows[1][k] for k in keys}
    summary = {'pairs': 1, 'ratios': ratios, 'ranges': {k: (v, v) for k, v in ratios.items()},
               'targets': {'rate': 0.99, 'answered': 0.99, 'p99': 1.1},
               'cpu_on_percent': 90.0, 'cpu_off_percent': 70.0, 'cpu_added_percent': 20.0,
               'frames_hz': 30.0, 'cpu_per_frame_s': 0.0067, 'frame_cpu_p50_s': 0.0055,
               'pose_to_image_p99_s': 0.08, 'pose_to_publication_p99_s': 0.02, 'delay_s': 0.05}
    baseline = [{**r, 'thread_priority': 0, 'operator_rate_hz': 500.0} for r in rows]
    text = cost_section({'rows': rows + baseline, 'summary': summary, 'variant': 'idle',
                         'thread_priority': 50, 'hogs': 1, 'variants': {'idle': summary}})
    assert ("| operator's poses a second | 1000.00 | 980.00 | 0.980 [0.98-0.98] | >= 0.99 "
            "(MISSED) |") in text
    assert ("| operator's round trip, p99 | 1.00 ms | 1.20 ms | 1.200 [1.20-1.20] | <= 1.1 "
            "(MISSED) |") in text
    assert ("| robot's ticks a second | 1000.00 | 1000.00 | 1.000 [1.00-1.00] | >= 0.99 "
            "(met) |") in text
    assert 'imaging adds 20 % at 30.0 frames a second, 6.7 ms of CPU a frame' in text
    assert "processes under SCHED_FIFO at priority 50" in text
    assert 'side by side, with 1 other process keeping a core busy throughout;' in text
    summary['ranges']['robot_rate_hz'] = (0.95, 1.05)  # the groups spread across the target
    assert ("| robot's ticks a second | 1000.00 | 1000.00 | 1.000 [0.95-1.05] | >= 0.99 "
            "(met by the median only) |") in cost_section({'rows': rows, 'summary': summary,
                                                           'variant': 'idle', 'hogs': 0,
                                                           'thread_priority': 50})
    assert '80 ms at the operator over the 50 ms link (target 100 ms)' in text


def test_the_cost_section_sets_each_way_of_sharing_the_cores_side_by_side():
    ratios = {'operator_rate_hz': 0.995, 'robot_rate_hz': 1.0, 'robot_tick_p99_s': 1.05,
              'commands_hz': 0.99}
    idle = {'ratios': ratios, 'frames_hz': 28.0, 'pose_to_image_p99_s': 0.09}
    nice = {'ratios': {**ratios, 'robot_tick_p99_s': 1.4}, 'frames_hz': 30.0,
            'pose_to_image_p99_s': 0.07}
    idle_name, nice_name = label('idle', 50), label('5', 0)
    text = '\n'.join(variants_section({'variants': {idle_name: idle, nice_name: nice}}))
    assert ('| loops at SCHED_FIFO 50, imager at SCHED_IDLE | 0.995 | 1.000 | 1.050 | 0.990 | '
            '28.0 | 90 ms |' in text)
    assert ('| loops at normal scheduling, imager at niceness +5 | 0.995 | 1.000 | 1.400 | 0.990 '
            '| 30.0 | 70 ms |' in text)
    assert variants_section({'variants': {idle_name: idle}}) == []  # one: the table above
