"""A ContactModel message's leaf fields, for the driver's tests (``model_fields``, by name)."""
from haptic_contract.contact_model import Kind, model_fields

UP = (0.0, 0.0, 1.0)


def fields(planes=(), *, kind=Kind.PLANES, count=None, frame='world', limit=10.0,
           valid_for=0.01, radius=0.002, tip=(0.0, 0.0, 0.0), stamp=(5, 0),
           wrench=(0.0,) * 6):
    """Return the leaf fields of a ContactModel; each plane (point, normal, K, C, tool_point)."""
    return list(model_fields((*stamp, frame), 'box', kind, planes, limit, valid_for, radius, tip,
                             wrench, plane_count=count))


def plane(point=(0.0, 0.0, 0.0), normal=UP, stiffness=1000.0, damping=0.0,
          tool_point=(0.0, 0.0, 0.0)):
    return (point, normal, (stiffness,) * 3, (damping,) * 3, tool_point)
