"""Fuzzing campaign, CI budget (issue 14): generated and mutated expressions, numbers, unit
strings and model files through the reader, derive and the JSON output. Each input is
accepted, or refused with the project's own one-line error, within its time limit.

The long campaign (10^5 inputs, with counts) is benchmarks/fuzz_campaign.py.
"""

from __future__ import annotations

import pytest
from fuzz_inputs import (
    answer_files,
    derive_json,
    expressions,
    model_files,
    number_texts,
    quantities,
    read_answer_text,
    read_expression,
    read_model_text,
    run_input,
    unicode_expressions,
    unit_strings,
)
from hypothesis import HealthCheck, given, settings

from lagrangian.model.units import check_unit, parse_quantity


# deterministic in CI (the campaign script explores at random); generous limits, as CI
# machines are slow: a hang is minutes, the limits catch it
def fuzz(examples: int) -> settings:
    return settings(max_examples=examples, deadline=None, database=None, derandomize=True,
                    print_blob=True, suppress_health_check=list(HealthCheck))


@pytest.fixture(scope="module", autouse=True)
def _set_up_once():
    """pint's registry is built once (seconds on a busy machine), not in an input's time."""
    from lagrangian.model.units import registry

    registry()


def check(outcome, text):
    assert outcome.ok, f"{outcome.status} on {text!r}: {outcome.kind} {outcome.message}"


@fuzz(1000)
@given(expressions())
def test_expressions(text):
    check(run_input(lambda: read_expression(text), 5.0), text)


@fuzz(400)
@given(unicode_expressions())
def test_unicode_spellings(text):
    """θ̇, ½, ², ⁻¹, · and their misuses: accepted and printed back, or refused in one line."""
    check(run_input(lambda: read_expression(text), 5.0), text)


@fuzz(200)
@given(number_texts())
def test_numbers(text):
    check(run_input(lambda: read_expression(text), 5.0), text)


@fuzz(300)
@given(unit_strings(), quantities())
def test_unit_strings_and_values_with_units(unit, quantity):
    check(run_input(lambda: check_unit(unit, "unit", "fuzz.toml"), 5.0), unit)
    check(run_input(lambda: parse_quantity(quantity, "m", "--set x"), 5.0), quantity)


@fuzz(300)
@given(model_files())
def test_model_files_read(text):
    check(run_input(lambda: read_model_text(text), 10.0), text)


@fuzz(200)
@given(answer_files())
def test_answer_files_read(text):
    check(run_input(lambda: read_answer_text(text), 10.0), text)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


@fuzz(100)
@given(text=model_files())
def test_model_files_derive_to_json(text, folder):
    check(run_input(lambda: derive_json(text, folder), 30.0), text)
