"""The examples in the public docstrings run and print what they say."""

import doctest

import lagrangian
import lagrangian.api.system


def test_public_docstring_examples():
    for module in (lagrangian, lagrangian.api.system):
        failures, _ = doctest.testmod(module)
        assert failures == 0, module.__name__
