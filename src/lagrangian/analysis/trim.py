"""Trim: the input values u* that make a requested state an equilibrium, f(q0, 0; u*) +
E u*_c = Phi_q^T lambda (E the generalized forces of inputs on coordinates), solved by least
squares over the inputs (and the multipliers), the residual checked; then the linear model there.

An input is a parameter or a load's one parameter (cart_pendulum's F: its value in the model
file does not matter, the trim replaces it), or a coordinate (a generalized force on it, 0 in
the model). A state that no input can hold is refused, naming the coordinate the residual
stays on."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..compile.at_rest import AtRestFunctions
from ..errors import ModelError
from ..model.inputs import input_parameter
from .equilibria import resolve_equilibrium
from .linearization import LinearModel, input_columns, linear_model_at

# A residual below this fraction of the forces at play counts as balanced.
_BALANCED = 1e-9
_ITERATIONS = 6


class _Held:
    """AtRestFunctions with constant generalized forces added to f (inputs on coordinates held
    at their trim); everything else the wrapped functions'."""

    def __init__(self, functions: AtRestFunctions, force: np.ndarray):
        self._functions, self._force = functions, force

    def evaluate(self, q, t: float = 0.0, parameters=None) -> dict[str, np.ndarray]:
        out = dict(self._functions.evaluate(q, t, parameters))
        out["forcing"] = out["forcing"] + self._force
        return out

    def __getattr__(self, name: str):
        return getattr(self._functions, name)


def trimmed_linear_model(functions: AtRestFunctions, about: Mapping[str, float] | None,
                         inputs: Sequence[str],
                         rebuild: Callable[[dict[str, float]], AtRestFunctions]) -> LinearModel:
    """trimmed_linear_model without numpy's warnings: an overflow (F = 1e308) is judged by the
    residual and the linear model's own finiteness check, in one line."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return _trimmed(functions, about, inputs, rebuild)


def _trimmed(functions, about, inputs, rebuild) -> LinearModel:
    """The linear model about ``about`` with the ``inputs`` at their trim (``trim`` and
    ``nominal_inputs`` of the result: the values that hold the state, the model's own). Where
    the model's own values hold it, those are the trim; else least squares over the inputs.
    ``rebuild`` gives the functions at other parameter values (a parameter input's trim)."""
    model = functions.model
    names = [c.name for c in model.coordinates]
    parameters = dict(functions.parameters)
    symbols = [input_parameter(model, name) for name in inputs]
    nominal = np.array([0.0 if s is None else float(parameters[str(s)]) for s in symbols])
    try:  # the model's own values hold it (the balance checked again by linear_model_at)
        q, multipliers = resolve_equilibrium(functions, about)
        return _model(functions, q, multipliers, inputs, nominal, nominal, parameters)
    except ModelError as refusal:
        if not about:
            raise
        first = refusal
    from ..model.values import resolve_state

    state = resolve_state(model, about, field="about", velocities=False, time=False)
    q0 = state.q_array()
    on_coordinate = np.zeros((len(names), len(inputs)))
    for k, (name, symbol) in enumerate(zip(inputs, symbols, strict=True)):
        if symbol is None:
            on_coordinate[names.index(name), k] = 1.0
    u, current = nominal.copy(), functions
    for _ in range(_ITERATIONS):
        values = current.evaluate(q0)
        force = values["forcing"] + on_coordinate @ u
        jacobian = values["jacobian"]
        columns = input_columns(current.eom, q0, inputs, current.parameters)
        system = np.hstack([columns, -jacobian.T])
        solution = np.linalg.lstsq(system, -force, rcond=None)[0] \
            if np.all(np.isfinite(system)) and np.all(np.isfinite(force)) \
            else np.full(system.shape[1], np.nan)
        step = solution[:len(inputs)]
        residual = force + system @ solution
        scale = max(float(np.abs(force).max(initial=0.0)),
                    float(np.abs(columns * np.abs(u + step)).max(initial=0.0)), 1e-300)
        if not np.all(np.isfinite(solution)) or np.abs(residual).max(initial=0.0) > \
                _BALANCED * max(scale, 1.0):
            worst = int(np.argmax(np.abs(residual)))
            given = ", ".join(f"{n}={v:.6g}" for n, v in zip(names, q0, strict=True)
                              if n in state.given)
            raise ModelError(f"{given} is not an equilibrium for any value of the inputs "
                             f"({', '.join(inputs)}): a generalized force "
                             f"{residual[worst]:.3g} stays on {names[worst]}, which they do "
                             f"not reach", field="about") from None
        u = u + step
        parameters = {**parameters, **{str(s): float(x) for s, x in zip(symbols, u, strict=True)
                                       if s is not None}}
        if any(s is not None for s in symbols):
            current = rebuild(parameters)
        if np.all(np.abs(step) <= 1e-12 * (1 + np.abs(u))):
            break
    held = _Held(current, on_coordinate @ u) if np.any(on_coordinate @ u) else current
    try:
        q, multipliers = resolve_equilibrium(held, about)
    except ModelError:  # the inputs balanced q0 to first order only (a nonlinear input)
        raise first from None
    return _model(held, q, multipliers, inputs, u, nominal, parameters)


def _model(functions, q, multipliers, inputs, trim, nominal, parameters) -> LinearModel:
    from dataclasses import replace

    columns = input_columns(functions.eom, q, inputs, parameters)
    model = linear_model_at(functions, q, multipliers, inputs=inputs, input_columns=columns)
    return replace(model, trim={n: float(x) + 0.0 for n, x in zip(inputs, trim, strict=True)},
                   nominal_inputs={n: float(x) for n, x in zip(inputs, nominal, strict=True)})
