"""How the report writes numbers, lengths, dates and tables as text."""

import datetime
import math

__all__ = ['format_length', 'format_number', 'format_utc', 'markdown_table']


def markdown_table(header: list, rows: list) -> str:
    """Format a GitHub Markdown table; cells are printed with ``str``."""
    lines = ['| ' + ' | '.join(map(str, header)) + ' |',
             '|' + '|'.join('---' for _ in header) + '|']
    lines += ['| ' + ' | '.join(map(str, row)) + ' |' for row in rows]
    return '\n'.join(lines)


def format_number(value: float, digits: int = 3) -> str:
    """Format a number in ``digits`` significant figures; '-' for NaN or None."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return '-'
    return f'{value:.{digits}g}'


def format_length(value: float) -> str:
    """Format a length in metres: in mm from a micrometre up, else in m, 3 significant figures."""
    if value is None or math.isnan(value):
        return '-'
    return f'{value * 1e3:.3g} mm' if abs(value) >= 1e-6 else f'{value:.3g} m'


def format_utc(stamp: float) -> str:
    """Format a POSIX time as a UTC date and time to the minute."""
    return datetime.datetime.fromtimestamp(stamp, datetime.timezone.utc).strftime(
        '%Y-%m-%d %H:%M UTC')
