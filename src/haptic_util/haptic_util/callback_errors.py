"""A callback that raises is logged once per place it comes from, counted, and the node goes on.

Why: one bad message must not end a node, nor flood the log at 1 kHz. Each node decides what a
failed callback means for its output (an invalid state, zero force). The executor's spin and the
intra-process delivery both report here.
"""
import sys
import traceback

__all__ = ['callback_errors', 'log_callback_error']

_errors: dict = {}  # (exception type, file, line) -> count


def callback_errors() -> int:
    """How many callbacks raised in this process so far."""
    return sum(_errors.values())


def log_callback_error(error: Exception) -> None:
    """Count ``error``; print it with its traceback the first time its place raises."""
    frames = traceback.extract_tb(error.__traceback__)
    where = (type(error), frames[-1].filename, frames[-1].lineno) if frames else (type(error),)
    _errors[where] = _errors.get(where, 0) + 1
    if _errors[where] == 1:
        text = ''.join(traceback.format_exception(error)).rstrip()
        print(f'[ERROR] a callback raised; the node goes on (further ones from the same place '
              f'are counted, not printed):\n{text}', file=sys.stderr, flush=True)
