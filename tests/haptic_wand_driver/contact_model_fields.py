"""A ContactModel message's leaf fields, built by hand for the driver's tests."""
from haptic_wand_driver.contact_model import Kind

UP = (0.0, 0.0, 1.0)


def fields(planes=(), *, kind=Kind.PLANES, count=None, frame='world', limit=10.0,
           valid_for=0.01, radius=0.002, tip=(0.0, 0.0, 0.0), stamp=(5, 0),
           wrench=(0.0,) * 6):
    """Return the leaf fields of a ContactModel; each plane (point, normal, K, C, tool_point)."""
    values = [stamp[0], stamp[1], frame, 'box', int(kind),
              len(planes) if count is None else count]
    for plane in planes:
        for vector in plane:
            values += list(vector)
    values += [0.0] * (15 * (3 - len(planes)))
    return values + [limit, valid_for, radius, *tip, *wrench]


def plane(point=(0.0, 0.0, 0.0), normal=UP, stiffness=1000.0, damping=0.0,
          tool_point=(0.0, 0.0, 0.0)):
    return (point, normal, (stiffness,) * 3, (damping,) * 3, tool_point)
