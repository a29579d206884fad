"""The local model of a contact that the device renders itself (``haptic_msgs/ContactModel``).

Why: the wrench reaches the device one round trip after the pose it was computed for, and a held
force that lags the motion makes a stiff wall give energy back. The planes of the surface near the
tip, with their material, let the device compute the force against its current position at its
own servo rate (``haptic_wand_driver.local_rendering``). Call it after the pipeline's step, whose
law then holds the contact's state (the proxy's planes).

What is sent, per law (``ForceLaw.planes``): the normal law's tangent plane at the closest point,
the proxy's constraint planes, none for the paper's centroid law (``UNAVAILABLE``: the device
applies the wrench). Only within ``radius`` of a surface: farther out the model says ``FREE``,
valid while the tip stays nearer than the clearance, and every answer the watchdog refused says
``FREE`` with no room at all, so the device renders zero.
"""
from dataclasses import dataclass

from force_renderer.contact import Contact
from force_renderer.spring_damper import ForceLaw
from haptic_contract.contact_model import Kind, MAX_PLANES

__all__ = ['FREE', 'PLANES', 'UNAVAILABLE', 'LocalModel', 'local_model']

FREE, PLANES, UNAVAILABLE = Kind.FREE, Kind.PLANES, Kind.UNAVAILABLE


@dataclass(frozen=True)
class LocalModel:
    """What a device may render.

    ``kind``, up to three planes (``ForceLaw.planes``), and how far from the tip (m) it holds.
    """

    kind: int
    planes: tuple
    valid_radius: float


def local_model(law: ForceLaw, contact: Contact | None, answered: bool,
                radius: float) -> LocalModel:
    """Return the model of ``contact`` under ``law``.

    Parameters
    ----------
    answered : bool
        Whether the pipeline rendered this contact (its watchdog let it through).
    radius : float, m
        How near a surface the planes are sent, and how far the tip may move on them.
    """
    if contact is None or not answered:
        return LocalModel(FREE, (), 0.0)
    planes = law.planes(contact)
    if planes is None:
        return LocalModel(UNAVAILABLE, (), 0.0)
    if contact.distance >= radius and law.axis(contact) is None:  # not held by the law either
        return LocalModel(FREE, (), contact.distance)
    return LocalModel(PLANES, tuple(planes[:MAX_PLANES]), radius)
