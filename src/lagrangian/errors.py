"""Errors a user can meet, each naming where the problem is and what is wrong."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """"; did you mean 'x'?" naming the known name closest to ``name``, or "" when none is close."""
    close = difflib.get_close_matches(name, list(known), n=1)
    return f"; did you mean '{close[0]}'?" if close else ""


class LagrangianError(Exception):
    """Base class for every error the library raises on bad input (CLI exit status 2)."""


class ModelError(LagrangianError):
    """A model (file or builder) is invalid: names the source, the field and the problem."""

    def __init__(self, message: str, *, field: str | None = None, source: str | None = None):
        self.message = message
        self.field = field
        self.source = source
        super().__init__(self.__str__())

    def __str__(self) -> str:
        where = ": ".join(part for part in (self.source, self.field) if part)
        return f"{where}: {self.message}" if where else self.message

class DerivationError(LagrangianError):
    """The model is well formed but its equations cannot be formed (singular mass matrix, ...)."""
