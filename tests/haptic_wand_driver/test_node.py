"""The driver node's wiring, in-process: what its clocks do, without a launched loop."""
import time

from contact_model_fields import fields
import pytest
import rclpy
from rclpy.clock import ROSClock
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.time import Time
from std_msgs.msg import Header

from haptic_contract.contact_model import Kind
from haptic_util.qos import LATCHED_QOS
from haptic_util.stamps import to_nanoseconds
from haptic_wand_driver.local_rendering import DEADLINE
from haptic_wand_driver.node import WandDriverNode


@pytest.fixture
def driver(request, tmp_path):
    context = Context()
    rclpy.init(context=context, domain_id=98)
    extra = getattr(request, 'param', {})
    if extra.get('stats_file') == 'PER_TEST':  # a record in this test's own folder
        extra = {**extra, 'stats_file': str(tmp_path / 'stats.npz')}
    node = WandDriverNode(context=context, parameter_overrides=[
        rclpy.parameter.Parameter(name, value=value) for name, value in
        {'experiment': 'hold', 'wait_for_wrench': False, 'min_subscribers': 0, **extra}.items()])
    yield node
    node.destroy_node()
    rclpy.try_shutdown(context=context)


def test_a_backward_step_of_the_system_clock_does_not_stop_the_wand(driver, monkeypatch):
    clock = ROSClock()  # ROS time set tick by tick: 1 ms forward, then 10 s back once
    clock._set_ros_time_is_active(True)
    monkeypatch.setattr(driver, 'get_clock', lambda: clock)
    for k in range(100):
        clock.set_ros_time_override(Time(nanoseconds=1_800_000_000_000_000_000 + k * 1_000_000
                                         - (10_000_000_000 if k > 50 else 0)))
        driver.tick()
    assert driver.stats.poses > 90


def test_rendering_locally_it_takes_the_model_alone_and_holds_the_wrench_of_a_law_without_one(
        driver):
    assert {s.topic_name for s in driver.subscriptions} == {'/wand/contact_model'}
    driver.tick()  # open loop: the session runs from the first tick
    pose = driver._last_probe_ns  # the stamp of the pose just published, which it answers
    model = fields(kind=Kind.UNAVAILABLE, stamp=divmod(pose, 1_000_000_000),
                   wrench=(1.0, 0.0, -0.5, 0.0, 0.0, 0.0))
    driver.on_model(model)
    state = driver.device.read(driver._device_time())
    force, torque = driver.renderer.wrench(driver._device_time(), [*state.position, 0.0, 0.0],
                                           [0.0] * 5, 2.5e-4)
    assert force == pytest.approx((1.0, 0.0, -0.5)) and torque == (0.0, 0.0, 0.0)
    assert driver.stats.answers == 1


def test_the_session_start_is_latched_with_the_instant_the_script_s_clock_started(driver):
    """A subscriber that joins after the session began still hears when it began."""
    before = time.time_ns()
    driver.tick()  # open loop: the session starts at this tick
    after = time.time_ns()
    listener = rclpy.create_node('late_listener', context=driver.context)
    heard = []
    listener.create_subscription(Header, '/wand/session_start', heard.append, LATCHED_QOS)
    executor = SingleThreadedExecutor(context=driver.context)
    executor.add_node(listener)
    deadline = time.monotonic() + 5.0
    while not heard and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    listener.destroy_node()
    assert len(heard) == 1
    assert before <= to_nanoseconds(heard[0].stamp) <= after
    assert heard[0].frame_id == driver.params.frame_id


def set_clocks(driver, monkeypatch, start_ns: int) -> tuple:
    """Drive both of the driver's clocks by hand: ROS time, and the device's a fixed way behind.

    Returns the ROS clock to set and the device's clock at ``start_ns``.
    """
    clock = ROSClock()
    clock._set_ros_time_is_active(True)
    device_start = time.monotonic() + 0.1  # the wand has been read at the monotonic clock
    behind = start_ns * 1e-9 - device_start
    monkeypatch.setattr(driver, 'get_clock', lambda: clock)
    monkeypatch.setattr(driver, '_device_time', lambda: clock.now().nanoseconds * 1e-9 - behind)
    clock.set_ros_time_override(Time(nanoseconds=start_ns))
    return clock, device_start


# A stamp whose seconds plus nanoseconds in floats fall below its nanoseconds in floats.
START = 1_800_000_000_001_000_123
assert 1_800_000_000 + 1_000_123e-9 < START * 1e-9


@pytest.mark.parametrize('driver', [{'hold_while_late': 0.1}], indirect=True)
def test_the_newest_model_holds_until_the_next_pose_is_sent_then_lives_its_lifetime(
        driver, monkeypatch):
    clock, device_start = set_clocks(driver, monkeypatch, START)
    driver.tick()
    driver.on_model(fields(stamp=divmod(START, 1_000_000_000), valid_for=0.01))
    assert driver.renderer.packed[0, DEADLINE] == pytest.approx(device_start + 0.1, abs=1e-6)
    clock.set_ros_time_override(Time(nanoseconds=START + 1_000_000))
    driver.tick()  # the next pose, on time: no answer to it comes
    assert driver.renderer.packed[0, DEADLINE] == pytest.approx(device_start + 0.01, abs=1e-6)


@pytest.mark.parametrize('driver', [{'hold_while_late': 0.1, 'rendering': 'remote',
                                     'passivity': False}],
                         indirect=True)
def test_a_held_wrench_no_answer_follows_stops_at_its_lifetime_with_the_hold_on(
        driver, monkeypatch):
    """The wrench of the newest pose, then a pose on time that nothing answers."""
    clock, _ = set_clocks(driver, monkeypatch, START)
    driver.tick()
    driver.on_wrench([*divmod(START, 1_000_000_000), 'world', 0.0, 0.0, 2.0, 0.0, 0.0, 0.0])
    clock.set_ros_time_override(Time(nanoseconds=START + 1_000_000))
    driver.tick()
    driver.device.applied()  # from here on
    clock.set_ros_time_override(Time(nanoseconds=START + 21_000_000))
    driver.device.read(driver._device_time())
    force = driver.device.applied()[0]
    pushing = force[2] / 2.0 * 80  # of the 80 servo periods of those 20 ms
    assert 36 <= round(pushing) <= 37  # 9 ms on, to its lifetime; the period at its edge: either


@pytest.mark.parametrize('driver', [{'rendering': 'remote', 'passivity': False,
                                     'wrench_timeout': 0.5, 'stats_file': 'PER_TEST'}],
                         indirect=True)
def test_the_record_maps_each_force_edge_with_the_clock_offset_of_its_own_time(
        driver, monkeypatch):
    """The system clock steps 0.19 s forward while a force is on; a zero wrench ends it later."""
    clock = ROSClock()
    clock._set_ros_time_is_active(True)
    start = time.monotonic() + 0.1  # the wand has been read at the monotonic clock
    device = [start]  # the device's clock [s], which no step of the system clock moves
    monkeypatch.setattr(driver, 'get_clock', lambda: clock)
    monkeypatch.setattr(driver, '_device_time', lambda: device[0])
    ros = [START]

    def tick_after(seconds: float, step_ns: int = 0) -> None:
        device[0] += seconds
        ros[0] += round(seconds * 1e9) + step_ns
        clock.set_ros_time_override(Time(nanoseconds=ros[0]))
        driver.tick()

    def wrench(force_z: float) -> None:
        driver.on_wrench([*divmod(ros[0], 1_000_000_000), 'world', 0.0, 0.0, force_z, 0.0,
                          0.0, 0.0])

    tick_after(0.0)  # the session starts
    wrench(2.0)
    for step_ns in (0, 190_000_000, 0):
        tick_after(0.001, step_ns)
    wrench(0.0)
    tick_after(0.001)
    record = driver._force_edges()
    on_device, off_device = (t for t, _ in driver.device.force_edges)
    # The truth in integer nanoseconds. The driver reads the offset in float seconds: ROS
    # time's nanoseconds as a float (256 ns apart at this epoch), scaled, then less the
    # device's clock, each rounding: 0.53 µs at most in 200000 random draws of that arithmetic
    # (448 ns seen in this test).
    on_ns, off_ns = (START + round((t - start) * 1e9) for t in (on_device, off_device))
    assert abs(int(record['force_on_ns'][0]) - on_ns) <= 1000
    assert abs(int(record['force_off_ns'][0]) - (off_ns + 190_000_000)) <= 1000
    assert record['force_on_ns'].size == record['force_off_ns'].size == 1
    assert record['clock_steps'] == 1
