"""The argparse types that read an option's number or word (``cli._options``)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from impact_balance.cli._options import CommandLineError, number_or_words

WORDS = ("off", "controller")


def _type():
    return number_or_words(
        "--option", WORDS, lambda value: 0.0 < value <= 1.0, "not a number", "outside", "kind"
    )


@given(st.floats(allow_nan=True, allow_infinity=True))
def test_a_number_is_taken_exactly_when_finite_and_inside(value):
    check = _type()
    text = repr(value)
    if math.isfinite(value) and 0.0 < value <= 1.0:
        assert check(text) == value
    else:
        with pytest.raises(CommandLineError) as raised:
            check(text)
        assert (raised.value.field, raised.value.value, raised.value.reason) == (
            "--option",
            text,
            "outside",
        )


@pytest.mark.parametrize("word", WORDS)
def test_the_words_pass_as_they_are(word):
    assert _type()(word) == word


@given(st.text().filter(lambda text: text not in WORDS))
def test_text_that_is_no_number_names_the_option_and_the_text(text):
    try:
        float(text)
    except ValueError:
        with pytest.raises(CommandLineError) as raised:
            _type()(text)
        assert raised.value.field == "--option"
        assert raised.value.value == text
        assert raised.value.reason == "not a number"


def test_the_type_carries_its_name_for_argparse():
    assert _type().__name__ == "kind"
