"""Verdicts on ``[statics]``: the load magnitudes (and reactions) that hold a mechanism at rest in
a configuration, against the System's statics (delta W = 0, analysis/statics.py), to the
precision written. A wrong value is explained where one slip reproduces it: the load's sign, a
load, weight or spring left out, or a weight's or spring's potential with the wrong sign.
"""

from __future__ import annotations

import math

from ..errors import ModelError
from ..model.expressions import as_expression
from ..model.units import is_angle_unit
from .final_reading import FinalAnswers, Written, agrees
from .finding import Finding

STATICS_CODES = ("statics_value", "statics_load", "statics_potential")
# The seed module's words (misconceptions table) for the slip that explains a value.
_LOAD_QUESTION = ("Did I do virtual work for every non-potential load? Project each load with "
                  "δW = Q · δq.")
_SIGN_QUESTION = ("Does V increase as the body rises? Take V positive upward and be consistent "
                  "with the datum.")


def check_statics(system, final: FinalAnswers, source: str) -> list[Finding]:
    """Findings on every value of [statics] (items statics.P, statics.lambda_loop_x)."""
    if not final.statics:
        return []
    model = system.equations_of_motion().model
    at = dict(final.statics_at or ())
    unknowns = [name for name, _ in final.statics if not name.startswith("lambda_")
                or name not in _multipliers(model)]
    report = _solve(system, at, unknowns, None, source)
    ours = {**report.solved, **report.reactions}
    units = {name: report.units.get(name) or "" for name in ours}
    where = _where(model, report)
    slips: list | None = None
    findings = []
    for name, written in final.statics:
        item, true = f"statics.{name}", ours[name]
        unit = f" {units[name]}" if units[name] else ""
        scale = max([abs(v) for v in ours.values()] + [1.0])
        what = "holds it" if name in report.solved else "is the reaction"
        if agrees(written, true, scale):
            findings.append(Finding(item, "correct", None,
                                    f"{name} = {written.text} {what} at {where}: ours is "
                                    f"{true:.6g}{unit}, compared {written.precision}.", None))
            continue
        if slips is None:
            slips = _slips(system, at, unknowns, model)
        code, hint = _explained(name, written, true, slips)
        findings.append(Finding(
            item, "wrong", code, f"{name} = {written.text} at {where}: ours is {true:.6g}{unit} "
            f"(delta W = 0 for every admissible delta q), compared {written.precision}.{hint}",
            f"{true:.6g}{unit}"))
    return findings


def _solve(system, at, unknowns, parameters, source: str):
    """The System's statics; its refusals name the answer file's table."""
    try:
        return system.statics(at, unknowns, parameters)
    except ModelError as error:
        field = {"configuration": "statics.at"}.get(error.field or "", "statics")
        raise ModelError(error.message, field=field, source=source) from None


def _multipliers(model) -> set[str]:
    return {f"lambda_{c.name}" for c in model.constraints}


def _slips(system, at, unknowns, model) -> list[tuple[str, str, dict[str, float]]]:
    """(code, words, values) for each slip: one source left out (its magnitude 0) or reversed
    (its magnitude negated), with the values that would then hold the mechanism."""
    values = {p.name: p.value for p in model.parameters if p.value is not None}
    candidates = []
    gravity = model.gravity
    if gravity is not None and as_expression(gravity.magnitude).is_Symbol:
        g = str(gravity.magnitude)
        candidates.append((g, "statics_potential", "the weights",
                           f"each weight's potential -m {g} h"))
    for spring in model.springs:
        k = as_expression(spring.stiffness)
        if k.is_Symbol:
            candidates.append((str(k), "statics_potential", f"the spring '{spring.name}'",
                               f"the spring '{spring.name}''s potential"))
    for load in model.loads:
        magnitude = (load.force if hasattr(load, "force") else
                     load.moment if hasattr(load, "moment") else (load.torque,))
        symbols = {str(s) for e in magnitude for s in as_expression(e).free_symbols}
        owned = [p for p in model.parameters if p.name in symbols]
        if len(owned) == 1:
            candidates.append((owned[0].name, "statics_load", f"the load '{load.name}'",
                               f"the load '{load.name}'"))
    slips = []
    for parameter, code, left_out, reversed_ in candidates:
        if parameter in unknowns or values.get(parameter) in (None, 0):
            continue
        for factor, words in ((0.0, f"without {left_out} ({parameter} = 0)"),
                              (-1.0, f"with {reversed_} of the wrong sign")):
            try:
                report = system.statics(at, unknowns, {parameter: factor * values[parameter]})
            except ModelError:  # the slip leaves nothing to solve for: it explains nothing
                continue
            slips.append((code, words, {**report.solved, **report.reactions}))
    return slips


def _explained(name: str, written: Written, true: float, slips) -> tuple[str, str]:
    """The code and the hint for a wrong value: the first slip that reproduces it."""
    if true != 0 and agrees(written, -true):
        return "statics_load", (f" Yours has the opposite sign: which way does {name} "
                                        f"do positive work? {_LOAD_QUESTION}")
    for code, words, values in slips:
        value = values.get(name)
        if value is not None and not math.isclose(value, true, rel_tol=1e-9) \
                and agrees(written, value):
            question = _SIGN_QUESTION if code == "statics_potential" else _LOAD_QUESTION
            return code, f" Yours is the value {words}, {value:.6g}: {question}"
    return "statics_value", (" Is delta W = 0 for every admissible delta q, with every load's, "
                             "weight's and spring's virtual work and no work by ideal reactions?")


def _where(model, report) -> str:
    """The configuration: given coordinates, then those found from the constraints."""
    def shown(name: str, value: float) -> str:
        unit = model.coordinate(name).unit
        if is_angle_unit(unit):
            return f"{name} = {value:.6g} rad ({math.degrees(value):.4g} deg)"
        return f"{name} = {value:.6g} {unit or 'm'}"

    given = [shown(k, v) for k, v in report.configuration.items()
             if k not in report.found_from_constraints]
    found = [shown(k, report.configuration[k]) for k in report.found_from_constraints]
    return ", ".join(given) + (f" ({', '.join(found)} from the constraints)" if found else "")
