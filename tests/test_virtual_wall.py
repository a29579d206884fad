"""The closed-loop simulator against closed-form motion, and its servo timing model."""

from ground_truth.virtual_wall import Device, HalfSpace, OperatorHand, ServoTiming, simulate
import numpy as np
import pytest

from force_renderer.errors import ForceRendererError

FAR_WALL = HalfSpace(origin=(0.0, 0.0, -10.0))


def constant(force):
    """A renderer that always commands `force` and records what it was given."""
    calls = []

    def render(contact, velocity, now):
        calls.append((contact, velocity, now))
        return np.asarray(force, dtype=float)
    render.calls = calls
    return render


def test_hand_alone_is_an_exact_damped_oscillator():
    mass, damping, stiffness, hand_damping = 0.2, 0.5, 400.0, 1.5
    target = np.array([0.01, -0.02, 0.03])
    run = simulate(constant((0.0, 0.0, 0.0)), FAR_WALL, Device(mass, damping),
                   OperatorHand(stiffness, hand_damping, lambda t: target), duration=0.3,
                   start=np.zeros(3), start_velocity=(0.1, 0.0, -0.2))
    # Underdamped solution of m x'' + c x' + k (x - target) = 0, written out per axis.
    c = damping + hand_damping
    decay = c / (2 * mass)
    frequency = np.sqrt(stiffness / mass - decay ** 2)
    offset0, speed0 = -target, np.array([0.1, 0.0, -0.2])
    t = run.time[:, None]
    b_coefficient = (speed0 + decay * offset0) / frequency
    expected = target + np.exp(-decay * t) * (offset0 * np.cos(frequency * t)
                                              + b_coefficient * np.sin(frequency * t))
    np.testing.assert_allclose(run.position, expected, atol=1e-12)


def test_constant_force_on_a_damped_mass_and_its_exact_port_energy():
    mass, damping, force = 0.1, 2.0, np.array([0.0, 0.5, -1.0])
    run = simulate(constant(force), FAR_WALL, Device(mass, damping),
                   OperatorHand(0.0, 0.0, lambda t: np.zeros(3)), duration=0.2, start=np.zeros(3))
    t = run.time[:, None]
    terminal = force / damping
    tau = mass / damping
    np.testing.assert_allclose(run.velocity, terminal * (1 - np.exp(-t / tau)), atol=1e-12)
    position = terminal * (t - tau * (1 - np.exp(-t / tau)))
    np.testing.assert_allclose(run.position, position, atol=1e-12)
    np.testing.assert_allclose(run.port_energy, -position @ force, atol=1e-13)


def test_one_axis_device_moves_and_works_only_along_its_axis():
    device = Device(0.1, 1.0, np.array([[0.0, 0.0, 1.0]]))
    run = simulate(constant((3.0, -2.0, 1.0)), FAR_WALL, device,
                   OperatorHand(0.0, 0.0, lambda t: np.zeros(3)), duration=0.05,
                   start=np.array([0.1, 0.2, 0.3]), start_velocity=(5.0, 5.0, 0.0))
    np.testing.assert_array_equal(run.position[:, :2], np.tile([0.1, 0.2], (run.time.size, 1)))
    np.testing.assert_allclose(run.port_energy, -(run.position[:, 2] - 0.3) * 1.0, atol=1e-14)


def test_servo_instants_period_and_jitter_are_deterministic_per_seed():
    hand = OperatorHand(0.0, 0.0, lambda t: np.zeros(3))

    def instants(timing, seed=0):
        return simulate(constant((0.0, 0.0, 0.0)), FAR_WALL, Device(), hand, duration=0.2,
                        start=np.zeros(3), timing=timing, seed=seed).sample_time

    np.testing.assert_allclose(np.diff(instants(ServoTiming())), 0.001, rtol=1e-9)
    jittered = ServoTiming(jitter=0.004)
    gaps = np.diff(instants(jittered))
    assert gaps.min() >= 0.001 - 1e-12 and gaps.max() <= 0.005 + 1e-12 and gaps.std() > 5e-4
    np.testing.assert_array_equal(instants(jittered, 3), instants(jittered, 3))
    assert not np.array_equal(instants(jittered, 3), instants(jittered, 4))


def test_delay_shifts_when_the_force_arrives():
    def step_at_10_ms(contact, velocity, now):
        return np.array([0.0, 0.0, 1.0 if now >= 0.010 - 1e-12 else 0.0])
    run = simulate(step_at_10_ms, FAR_WALL, Device(),
                   OperatorHand(0.0, 0.0, lambda t: np.zeros(3)), duration=0.03,
                   start=np.zeros(3), timing=ServoTiming(delay=0.0025))
    first = run.time[np.argmax(run.force[:, 2] > 0.0)]
    assert first == pytest.approx(0.0125, abs=1e-9)


def test_dropped_messages_repeat_the_last_delivered_state():
    render = constant((0.0, 0.0, 0.0))
    simulate(render, FAR_WALL, Device(), OperatorHand(0.0, 0.0, lambda t: np.zeros(3)),
             duration=1.0, start=np.zeros(3), start_velocity=(0.0, 0.0, 0.1),
             timing=ServoTiming(drop_probability=0.25), seed=1)
    stamps = np.array([contact.stamp for contact, _, _ in render.calls])
    nows = np.array([now for _, _, now in render.calls])
    repeated = np.mean(np.diff(stamps) == 0.0)
    assert 0.2 < repeated < 0.3
    assert np.all(stamps <= nows)


def test_contact_is_the_wall_s_exact_state_and_velocity_can_be_withheld():
    render = constant((0.0, 0.0, 0.0))
    simulate(render, HalfSpace(), Device(), OperatorHand(0.0, 0.0, lambda t: np.zeros(3)),
             duration=0.01, start=np.array([0.1, 0.0, -0.002]), give_velocity=False)
    contact, velocity, now = render.calls[0]
    assert velocity is None and now == 0.0
    assert contact.distance == pytest.approx(-0.002)
    np.testing.assert_allclose(contact.point, [0.1, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(contact.penetration, [0.0, 0.0, 0.002], atol=1e-15)


def test_half_space_distance_and_normalised_normal():
    wall = HalfSpace(origin=(0.0, 0.0, 1.0), normal=(0.0, 3.0, 4.0))
    distance, normal = wall(np.array([0.0, 0.6, 1.8]))
    assert distance == pytest.approx(1.0)
    np.testing.assert_allclose(normal, [0.0, 0.6, 0.8])
    np.testing.assert_allclose(wall.signed_distances(np.array([[0.0, 0.0, 1.0],
                                                               [0.0, -0.6, 0.2]])), [0.0, -1.0])


@pytest.mark.parametrize('build, name', [
    (lambda: HalfSpace(normal=(0.0, 0.0, 0.0)), 'HalfSpace.normal'),
    (lambda: Device(mass=0.0), 'Device.mass'),
    (lambda: Device(axes=np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])), 'Device.axes'),
    (lambda: ServoTiming(drop_probability=1.0), 'ServoTiming.drop_probability'),
    (lambda: ServoTiming(period=1e-6), 'ServoTiming.period'),
    (lambda: OperatorHand(-1.0, 0.0, lambda t: np.zeros(3)), 'OperatorHand.stiffness'),
])
def test_bad_settings_name_the_field(build, name):
    with pytest.raises(ForceRendererError, match=name):
        build()
