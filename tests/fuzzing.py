"""How many examples a property test draws: its own count, or ten times that under ``make fuzz``.

A test's ``settings(max_examples=...)`` overrides any profile's, so the scale is applied here.
"""
import os

__all__ = ['examples']

FUZZ_SCALE = 10


def examples(count: int) -> int:
    """Return ``count``, scaled up when the ``fuzz`` Hypothesis profile is selected."""
    return count * FUZZ_SCALE if os.environ.get('HYPOTHESIS_PROFILE') == 'fuzz' else count
