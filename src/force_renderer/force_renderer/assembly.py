"""The force renderer built from its parameters, without rclpy: its node and the benches call it.

``force_law`` reads the scene for the objects' materials (the tool's face, and the laws that need
the surface itself), ``force_pipeline`` puts the law behind the watchdog, the passivity
controller and saturation, and ``state_contact`` reads a collision state's fields into the
renderer's ``Contact``.
"""
from typing import Callable

import numpy as np

from force_renderer.contact import Contact, FaceContact
from force_renderer.materials import PerObjectLaw
from force_renderer.params import ForceRendererParams
from force_renderer.passivity import passivity_warning
from force_renderer.pipeline import ForcePipeline, PipelineConfig
from force_renderer.probe import ProbeSpringDamper
from force_renderer.proxy import GodObjectProxy
from force_renderer.spring_damper import CentroidSpringDamper, ForceLaw, SpringDamper
from haptic_contract.collision_state import contact_fields, face_fields
from haptic_contract.streams import stamp_ns
from haptic_util.paths import resolve_path

__all__ = ['force_law', 'force_pipeline', 'passivity_warnings', 'state_contact']


def force_law(params: ForceRendererParams,
              announce: Callable[[str], None] = lambda line: None) -> tuple[ForceLaw, list]:
    """Build the force law; return it and every (stiffness, damping) it renders with.

    ``announce`` hears what loading the scene says (the proxy's law compiles its kernels).
    Raises ValueError for a law the scene does not allow.
    """
    default = (params.stiffness, params.damping)
    if not params.scene_file:
        if params.law != 'normal':
            raise ValueError(f'law {params.law!r} needs parameter scene_file')
        return SpringDamper(*default), [default]
    scene_path = resolve_path(params.scene_file, what='parameter scene_file')
    from collision_engine import read_scene
    spec = read_scene(scene_path)
    materials = {o.name: (tuple(o.material.stiffness), tuple(o.material.damping))
                 for o in spec.objects if o.material is not None}
    gains = [default, *materials.values()]
    if spec.tool is not None:
        if params.law != 'normal':
            raise ValueError(f'law {params.law!r} renders a point tip, and the scene '
                             f'{scene_path} mounts a tool: use the normal law')
        laws = {name: ProbeSpringDamper(*gain) for name, gain in materials.items()}
        return PerObjectLaw(laws, ProbeSpringDamper(*default)), gains
    if params.law == 'proxy':
        from collision_engine import load_scene
        scene = load_scene(scene_path, announce=announce)  # warmed up

        def signed_distance(point):
            result = scene.query(point)
            return result.distance, result.normal
        return GodObjectProxy(*default, signed_distance), [default]
    if params.law == 'centroid':
        from force_renderer.centroids import vertex_centroids
        centroids = vertex_centroids(spec)
        laws = {name: CentroidSpringDamper(*materials.get(name, default), centroid)
                for name, centroid in centroids.items()}
        return PerObjectLaw(laws, SpringDamper(*default)), gains
    laws = {name: SpringDamper(*gain) for name, gain in materials.items()}
    return PerObjectLaw(laws, SpringDamper(*default)), gains


def force_pipeline(params: ForceRendererParams, law: ForceLaw) -> ForcePipeline:
    """Return ``law`` behind the watchdog, the passivity controller and saturation."""
    return ForcePipeline(law, PipelineConfig(
        force_limit=params.force_limit, passivity=params.passivity,
        max_damping=params.max_damping, servo_period=params.servo_period,
        timeout=params.watchdog_timeout))


def passivity_warnings(params: ForceRendererParams, gains: list) -> list:
    """Return a warning for each (stiffness, damping) the device cannot render passively."""
    warnings = (passivity_warning(stiffness, params.device_damping, params.servo_period, damping)
                for stiffness, damping in gains)
    return [warning for warning in warnings if warning]


def state_contact(fields) -> tuple[tuple, int, Contact]:
    """Return the header (sec, nanosec, frame), the stamp (ns) and the contact of a state."""
    header, name, status, distance, point, normal, tip = contact_fields(fields)
    stamp = stamp_ns(fields)
    return header, stamp, Contact.from_floats(distance, point, normal, tip, name, stamp * 1e-9,
                                              status, _face(fields))


def _face(fields) -> FaceContact | None:
    """Return the tool's face from a CollisionState's leaves, or None when it has no tool."""
    distance, points, normals, orientation = face_fields(fields)
    if not distance:
        return None
    from collision_engine.probe import rotation_matrix

    return FaceContact(np.array(distance), np.array(points).reshape(-1, 3),
                       np.array(normals).reshape(-1, 3), rotation_matrix(orientation))
