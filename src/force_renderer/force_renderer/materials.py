"""Each object's own material: the law of the object a contact is with.

A scene may hold a soft object beside a stiff one; the renderer then picks, per contact, the law
built from that object's stiffness and damping (per world axis), and a default for the rest.
"""
from typing import Mapping

import numpy as np

from force_renderer.contact import Contact
from force_renderer.spring_damper import ForceLaw

__all__ = ['PerObjectLaw']


class PerObjectLaw:
    """A `ForceLaw` that dispatches on ``contact.object``.

    Parameters
    ----------
    laws : mapping of object name to ForceLaw
    default : ForceLaw
        For objects without a law of their own.
    """

    def __init__(self, laws: Mapping[str, ForceLaw], default: ForceLaw) -> None:
        self.laws = dict(laws)
        self.default = default

    def force(self, contact: Contact, velocity) -> np.ndarray:
        """Force on the tip, (3,) float, N, by the law of the contact's object."""
        return self._law(contact).force(contact, velocity)

    def torque(self, contact: Contact):
        """Return the torque of the contact's object's law; see `ForceLaw.torque`."""
        return self._law(contact).torque(contact)

    def axis(self, contact: Contact):
        """Return the axis of the contact's object's law; see `ForceLaw.axis`."""
        return self._law(contact).axis(contact)

    def planes(self, contact: Contact):
        """Return the planes of the contact's object's law; see `ForceLaw.planes`."""
        return self._law(contact).planes(contact)

    def _law(self, contact: Contact) -> ForceLaw:
        return self.laws.get(contact.object, self.default)
