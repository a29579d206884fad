"""The defaults two nodes must agree on, owned here once.

The driver's device and the force renderer both need the device's force limit, its physical
damping (the renderer's passivity bound assumes the damping the device has) and the loop's tick
(the pose rate, the renderer's servo period); the leader sends the same force limit with its
models. Each node's parameters dataclass takes its default from here, and its YAML file repeats
it (``tests/test_parameter_files.py``); a user who overrides one sets both.
"""

__all__ = ['DEFAULT_SCENE', 'DEVICE_DAMPING', 'FORCE_LIMIT', 'LOOP_PERIOD', 'LOOP_RATE']

FORCE_LIMIT = 10.0  # [N] the device's largest force: saturation, and the models' limit
DEVICE_DAMPING = 2.0  # [N*s/m] the device's physical damping b, per axis
LOOP_RATE = 1000.0  # [Hz] the wand's poses, one tick of the loop each
LOOP_PERIOD = 1.0 / LOOP_RATE  # [s] 0.001, the renderer's servo period T
DEFAULT_SCENE = 'package://collision_engine/scenes/cuboid.yaml'  # the loop's scene
