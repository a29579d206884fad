"""The one error type of the force renderer's core, and the contract's checks raising it.

It subclasses `ValueError`, so callers that catch bad input generically still catch it; the message
always names the argument or field and says what is wrong with it. The checks themselves are the
toolkit's one set (``haptic_contract.checks``), bound here to raise it.
"""
import functools

from haptic_contract import checks, plane_law

__all__ = ['ForceRendererError', 'count', 'non_negative', 'per_axis', 'positive', 'saturate',
           'vector3']


class ForceRendererError(ValueError):
    """Bad input to the force renderer: a wrong shape, sign, or non-finite setting."""


vector3 = functools.partial(checks.vector3, error=ForceRendererError)
per_axis = functools.partial(checks.per_axis, error=ForceRendererError)
positive = functools.partial(checks.finite_number, minimum=0.0, strict=True,
                             error=ForceRendererError)
non_negative = functools.partial(checks.finite_number, minimum=0.0, error=ForceRendererError)
count = functools.partial(checks.whole_number, error=ForceRendererError)
saturate = functools.partial(plane_law.saturate, error=ForceRendererError)
