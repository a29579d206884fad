"""Haptic force rendering: the pure core (no rclpy, no message types).

A collision state becomes a `Contact`; a `ForceLaw` (`SpringDamper` along the surface normal, or a
`GodObjectProxy`) turns it into a force; `ForcePipeline` adds the watchdog, the passivity
controller and saturation, so the ROS node only converts messages.
"""

from force_renderer.contact import Contact
from force_renderer.errors import ForceRendererError, saturate
from force_renderer.passivity import passivity_bound, passivity_warning, PassivityController
from force_renderer.pipeline import ForcePipeline, PipelineConfig
from force_renderer.proxy import GodObjectProxy
from force_renderer.spring_damper import CentroidSpringDamper, ForceLaw, SpringDamper
from force_renderer.velocity import VelocityEstimator
from force_renderer.watchdog import Reason, Watchdog

__all__ = [
    'CentroidSpringDamper',
    'Contact',
    'ForceLaw',
    'ForcePipeline',
    'ForceRendererError',
    'GodObjectProxy',
    'PassivityController',
    'PipelineConfig',
    'Reason',
    'SpringDamper',
    'VelocityEstimator',
    'Watchdog',
    'passivity_bound',
    'passivity_warning',
    'saturate',
]
