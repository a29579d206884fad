"""The one error type of the force renderer's core.

It subclasses `ValueError`, so callers that catch bad input generically still catch it; the message
always names the argument or field and says what is wrong with it.
"""

__all__ = ['ForceRendererError']


class ForceRendererError(ValueError):
    """Bad input to the force renderer: a wrong shape, sign, or non-finite setting."""
