"""The image written as CDR without a message object is the message rclpy would write.

The same length, read back as the same message (CDR's padding bytes are left unspecified).
"""

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message
from sensor_msgs.msg import Image

from ultrasound_sim.conversions import image_cdr

STAMP_NS = 1_795_710_471_614_410_850


@pytest.mark.parametrize('shape', [(256, 256), (3, 5), (0, 4)])
def test_the_message_is_rclpys_own(shape):
    pixels = np.random.default_rng(7).integers(0, 256, shape, dtype=np.uint8)
    data = image_cdr(STAMP_NS, 'ultrasound_probe', pixels)
    message = Image()
    message.header.stamp.sec, message.header.stamp.nanosec = divmod(STAMP_NS, 1_000_000_000)
    message.header.frame_id = 'ultrasound_probe'
    message.height, message.width = shape
    message.encoding, message.is_bigendian, message.step = 'mono8', 0, shape[1]
    message.data = pixels.tobytes()
    assert len(data) == len(serialize_message(message))
    assert deserialize_message(data, Image) == message


@pytest.mark.parametrize('pixels', [np.zeros((4, 4), np.float32), np.zeros((4, 4, 3), np.uint8)])
def test_what_is_not_mono8_is_refused(pixels):
    with pytest.raises(ValueError, match='uint8'):
        image_cdr(STAMP_NS, 'ultrasound_probe', pixels)
