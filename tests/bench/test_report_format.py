"""How the report writes numbers, lengths, dates and tables; expected strings typed by hand."""
import math

from report_generator.report_format import format_length, format_number, format_utc, markdown_table


def test_markdown_table():
    assert markdown_table(['a', 'b'], [[1, 'x'], [2.5, '']]) == (
        '| a | b |\n|---|---|\n| 1 | x |\n| 2.5 |  |')


def test_numbers_in_significant_figures_and_a_dash_for_nothing():
    assert format_number(0.0123456) == '0.0123'
    assert format_number(1234.5, 2) == '1.2e+03'
    assert format_number(math.nan) == '-'
    assert format_number(None) == '-'


def test_lengths_in_mm_from_a_micrometre_up_else_in_metres():
    assert format_length(0.0213) == '21.3 mm'
    assert format_length(-1e-6) == '-0.001 mm'
    assert format_length(1.41e-18) == '1.41e-18 m'
    assert format_length(math.nan) == '-'


def test_utc_to_the_minute():
    assert format_utc(0.0) == '1970-01-01 00:00 UTC'
    assert format_utc(86400.0 + 3661.0) == '1970-01-02 01:01 UTC'
