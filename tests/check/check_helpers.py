"""Shared helpers: systems are loaded once per session (deriving is the slow part)."""

from __future__ import annotations

import functools
from pathlib import Path

import lagrangian
from lagrangian.model.answer import parse_answer

ANSWERS = Path(__file__).parent / "answers"


@functools.cache
def system(name: str) -> lagrangian.System:
    return lagrangian.load(name)


def check_file(model: str, answer: str):
    return system(model).check(ANSWERS / answer)


def check_text(model: str, text: str):
    s = system(model)
    return s.check(parse_answer(text, s.model, source="<test>"))


def finding(report, item):
    found = [f for f in report.findings if f.item == item]
    assert found, f"no finding for {item}: {report!r}"
    return found[0]


