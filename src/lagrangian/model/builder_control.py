"""ModelBuilder's control laws ([control] in a model file): u = law(q, q_dot, t) on an input,
a coordinate (its generalized force, N or N m), a parameter or a load (u in the parameter's
unit), kept apart from the equations until a run closes the loop (a mixin of
builder.ModelBuilder, sharing its declarations)."""

from __future__ import annotations

from typing import Self

from ..errors import ModelError
from .inputs import input_parameter
from .model import Model


class ControlLawsMixin:
    """add_control_law, mixed into ModelBuilder (its _control, expression, _error, source)."""

    def add_control_law(self, name: str, law: object, *, field: str | None = None) -> Self:
        """u on the input ``name`` as an expression in t, the coordinates, their rates, the
        parameters and definitions (references as functions of t); one law per input."""
        field = field or f"control.{name}"
        if name in self._control:
            raise self._error(f"a second law for input '{name}'", field)
        self._control[name] = (self.expression(law, field), field)
        return self

    def _control_laws(self, model: Model) -> tuple:
        """The laws, each input name checked against the built model (a coordinate, a
        parameter, or a load with exactly one parameter)."""
        for name, (_, field) in self._control.items():
            try:
                input_parameter(model, name, field=field)
            except ModelError as exc:
                raise ModelError(exc.message.replace("inputs may be", "a law's input may be"),
                                 field=field, source=self.source) from None
        return tuple((name, law) for name, (law, _) in self._control.items())
