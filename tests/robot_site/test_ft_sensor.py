"""The simulated force/torque sensor: its filter's step response, its noise and its bias."""
import math

import numpy as np
import pytest

from robot_site.ft_sensor import FirstOrderLowPass, ForceTorqueSensor, ForceTorqueSensorConfig

QUIET = dict(force_noise=0.0, torque_noise=0.0)


def test_the_step_response_is_that_of_a_first_order_filter_at_the_bandwidth():
    sensor = ForceTorqueSensor(ForceTorqueSensorConfig(bandwidth=50.0, **QUIET))
    sensor.measure(0.0, [0.0, 0.0, 0.0])
    times = np.arange(1, 101) * 1e-3
    readings = np.array([sensor.measure(t, [0.0, 0.0, 10.0], [0.0, 0.2, 0.0]) for t in times])
    time_constant = 1.0 / (2.0 * math.pi * 50.0)
    np.testing.assert_allclose(readings[:, 0, 2], 10.0 * (1.0 - np.exp(-times / time_constant)),
                               rtol=1e-12)
    np.testing.assert_allclose(readings[:, 1, 1], 0.2 * (1.0 - np.exp(-times / time_constant)),
                               rtol=1e-12)
    assert np.all(readings[:, 0, :2] == 0.0)


def test_the_filter_reads_the_same_at_a_given_time_whatever_the_sample_times():
    def at_end(times):
        low_pass = FirstOrderLowPass(30.0, [0.0])
        previous = 0.0
        for time in times:
            output = low_pass.update(time - previous, [1.0])
            previous = time
        return output[0]

    irregular = np.sort(np.r_[np.random.default_rng(1).uniform(0.0, 0.1, 37), 0.1])
    assert at_end(irregular) == pytest.approx(at_end([0.1]), rel=1e-12)
    assert at_end([0.1]) == pytest.approx(1.0 - math.exp(-2 * math.pi * 30.0 * 0.1), rel=1e-12)


def test_at_rest_the_reading_is_the_bias_plus_noise_of_the_given_rms():
    config = ForceTorqueSensorConfig(force_bias=[0.3, -0.2, 0.1], torque_bias=[0.01, 0, 0],
                                     force_noise=0.05, torque_noise=0.002, seed=7)
    sensor = ForceTorqueSensor(config)
    samples = 20000
    readings = np.array([np.concatenate(sensor.measure(k * 1e-3, np.zeros(3)))
                         for k in range(samples)])
    rms = np.array([0.05] * 3 + [0.002] * 3)
    bias = np.array([0.3, -0.2, 0.1, 0.01, 0.0, 0.0])
    # Mean within 4 standard errors; the RMS within 4 % (its standard error is 0.5 %).
    assert np.all(np.abs(readings.mean(axis=0) - bias) < 4.0 * rms / math.sqrt(samples))
    np.testing.assert_allclose(readings.std(axis=0), rms, rtol=0.04)
    assert np.all(np.isfinite(readings))


def test_a_seed_gives_the_same_readings_and_another_seed_others():
    def readings(seed):
        sensor = ForceTorqueSensor(ForceTorqueSensorConfig(seed=seed))
        return [sensor.measure(k * 1e-3, [0.0, 0.0, 5.0]).force for k in range(50)]

    np.testing.assert_array_equal(readings(3), readings(3))
    assert not np.array_equal(readings(3), readings(4))


@pytest.mark.parametrize('fields, message', [
    (dict(force_noise=-0.1), 'force_noise must be finite >= 0'),
    (dict(torque_noise=math.nan), 'torque_noise must be finite >= 0'),
    (dict(bandwidth=0.0), 'bandwidth must be finite > 0'),
    (dict(force_bias=[0.0, 0.0]), 'force_bias must be 3 finite numbers'),
    (dict(seed=-1), 'seed must be an integer >= 0'),
    (dict(seed=1.5), 'seed must be an integer >= 0'),
])
def test_bad_configurations_are_refused(fields, message):
    with pytest.raises(ValueError, match=message):
        ForceTorqueSensorConfig(**fields)


def test_nan_input_and_a_clock_going_back_are_refused():
    sensor = ForceTorqueSensor()
    with pytest.raises(ValueError, match='force must be 3 finite numbers'):
        sensor.measure(0.0, [0.0, math.nan, 0.0])
    with pytest.raises(ValueError, match='torque must be 3 finite numbers'):
        sensor.measure(0.0, np.zeros(3), [math.inf, 0.0, 0.0])
    sensor.measure(1.0, np.zeros(3))
    with pytest.raises(ValueError, match='must not go back'):
        sensor.measure(0.9, np.zeros(3))
    with pytest.raises(ValueError, match='elapsed must be >= 0'):
        FirstOrderLowPass(10.0, [0.0]).update(math.nan, [1.0])
