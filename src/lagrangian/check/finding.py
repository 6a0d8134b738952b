"""One verdict on one item of an answer: the type every room of check/ reports in."""

from __future__ import annotations

from dataclasses import dataclass

from ..kinds import FindingStatus


@dataclass(frozen=True)
class Finding:
    """The verdict on one item; ``code`` is None when correct, ``expected`` our version."""

    item: str
    status: FindingStatus
    code: str | None
    message: str
    expected: str | None = None
    # what --hints-only says instead of the message: specific, and never the answer (None:
    # the module's question for the code, check/hints.py)
    hint: str | None = None

    def __post_init__(self):  # "correct" as written, checked: a misspelled status is an error
        object.__setattr__(self, "status", FindingStatus(self.status))


__all__ = ["Finding"]
