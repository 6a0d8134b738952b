"""[momenta], [conserved], [routhian] and [hamiltonian] of an answer, judged against the model's
own L (analysis/conserved.py, routh.py, hamilton.py), each wrong item with its own diagnosis.

- ``[momenta]``: ``x = "..."``, p = dL/dx_dot per coordinate (item ``p[x]``);
- ``[conserved]``: ``cyclic = ["phi"]`` (items ``cyclic[phi]``), ``quantities = ["..."]``
  claimed constant along every motion (items ``conserved[k]``: dF/dt = 0 with q_ddot from the
  equations, at random states and the model's parameter values);
- ``[routhian]``: ``cyclic = ["phi"]`` and ``R = "..."`` (R = sum p q_dot - L, in the kept
  coordinates and p_<name>) or ``L_R = "..."`` (= -R);
- ``[hamiltonian]``: ``H = "..."`` in q and p_<q>.
"""

from __future__ import annotations

from collections.abc import Mapping

import mpmath
import sympy as sp

from ..analysis.conserved import ConservedQuantities, conserved_quantities
from ..analysis.hamilton import hamiltonian_of, momentum_symbols
from ..analysis.routh import routhian_model
from ..errors import LagrangianError, ModelError
from ..kinds import InvariantKind
from ..model.answer import MECHANICS_TABLES, answer_expression, answer_names
from ..model.expressions import format_expression as fmt
from . import equivalence as eq
from .finding import Finding

MECHANICS_CODES = (
    "momentum_wrong", "not_cyclic", "cyclic_missing", "momentum_not_conserved",
    "energy_not_conserved", "not_conserved", "routhian_sign", "effective_potential",
    "routhian_wrong", "hamiltonian_in_velocities", "hamiltonian_inverse", "hamiltonian_wrong",
)


def check_mechanics(system, tables: Mapping[str, object], source: str) -> list[Finding]:
    """Findings on the answer's [momenta], [conserved], [routhian] and [hamiltonian]."""
    if not any(name in tables for name in MECHANICS_TABLES):
        return []
    eom = system.equations_of_motion()
    return _Mechanics(eom, tables, source).run()


class _Mechanics:
    def __init__(self, eom, tables: Mapping, source: str):
        self.eom, self.model, self.source = eom, eom.model, source
        self.tables = tables
        self.names = [c.name for c in self.model.coordinates]
        self.momenta = momentum_symbols(self.names)
        self.scope = {**answer_names(self.model), **{str(p): p for p in self.momenta}}
        self.points = eq.random_points(self.model, self.momenta)
        self.valued = eq.random_points(self.model, self.momenta, model_values=True)
        self._found: ConservedQuantities | None = None

    @property
    def found(self) -> ConservedQuantities:
        if self._found is None:
            self._found = conserved_quantities(self.eom)
        return self._found

    def fail(self, message: str, field: str) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    def expression(self, value: object, field: str) -> sp.Expr:
        if not isinstance(value, str):
            raise self.fail(f"expected an expression as a string, got {value!r}", field)
        parsed = answer_expression(value, self.scope, field, self.source)
        return sp.sympify(parsed)  # safe: a sympy object from the project's parser

    def table(self, name: str, allowed: tuple[str, ...]) -> Mapping:
        table = self.tables.get(name, {})
        if not isinstance(table, Mapping):
            raise self.fail(f"expected a table [{name}]", name)
        for key in table:
            if key not in allowed:
                raise self.fail(f"unknown key '{key}' (expected one of: {', '.join(allowed)})",
                                f"{name}.{key}")
        return table

    def names_list(self, value: object, field: str) -> list[str]:
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.fail("expected a list of coordinate names", field)
        for name in value:
            if name not in self.names:
                raise self.fail(f"'{name}' is not a coordinate (the model's: "
                                f"{', '.join(self.names)})", field)
        return list(value)

    def run(self) -> list[Finding]:
        findings: list[Finding] = []
        if "momenta" in self.tables:
            findings += self.momenta_findings()
        if "conserved" in self.tables:
            findings += self.conserved_findings()
        if "routhian" in self.tables:
            findings += self.routhian_findings()
        if "hamiltonian" in self.tables:
            findings += self.hamiltonian_findings()
        return findings

    # [momenta] -----------------------------------------------------------------------------

    def ours(self, name: str) -> sp.Expr:
        return sp.expand(self.eom.lagrangian.diff(self.model.coordinate(name).velocity))

    def momenta_findings(self) -> list[Finding]:
        table = self.table("momenta", tuple(self.names))
        findings = []
        for name in self.names:
            if name not in table:
                continue
            item, yours = f"p[{name}]", self.expression(table[name], f"momenta.{name}")
            ours = self.ours(name)
            if eq.identical(yours, ours, self.points):
                findings.append(Finding(item, "correct", None, f"{item} = dL/d{name}_dot "
                                        "matches.", None))
                continue
            findings.append(Finding(
                item, "wrong", "momentum_wrong",
                f"{item} is dL/d{name}_dot, the derivative of L = T - V with respect to the "
                f"rate; yours minus ours is {fmt(eq.display(yours - ours))}.", fmt(ours),
                hint=f"Is p[{name}] = dL/d{name}_dot, with every term of T that has "
                     f"{name}_dot (cross terms too)?"))
        return findings

    # [conserved] ---------------------------------------------------------------------------

    def cyclic_reason(self, name: str) -> str | None:
        """Why ``name`` is not cyclic (the terms of L it is in), None when it is."""
        return dict(self.found.not_cyclic).get(name)

    def conserved_findings(self) -> list[Finding]:
        table = self.table("conserved", ("cyclic", "quantities"))
        findings = []
        if "cyclic" in table:
            listed = self.names_list(table["cyclic"], "conserved.cyclic")
            for name in listed:
                findings.append(self.cyclic_finding(name))
            cyclic = [n for n in self.names if self.cyclic_reason(n) is None]
            left = [n for n in cyclic if n not in listed]
            if left:
                findings.append(Finding(
                    "cyclic", "wrong", "cyclic_missing",
                    f"{', '.join(left)} {'is' if len(left) == 1 else 'are'} cyclic too: L "
                    "does not depend on it (only on its rate).", ", ".join(cyclic),
                    hint="Which coordinates does L not contain (only their rates)?"))
        if "quantities" in table:
            values = table["quantities"]
            if not isinstance(values, list) or not values:
                raise self.fail("expected a list of expressions", "conserved.quantities")
            for k, value in enumerate(values, start=1):
                field = f"conserved.quantities[{k}]"
                findings.append(self.quantity_finding(f"conserved[{k}]",
                                                      self.expression(value, field)))
        return findings

    def cyclic_finding(self, name: str) -> Finding:
        item = f"cyclic[{name}]"
        reason = self.cyclic_reason(name)
        if reason is not None:
            return Finding(item, "wrong", "not_cyclic",
                           f"{name} is not cyclic: L depends on it through {reason}.", None,
                           hint=f"Does L contain {name} itself, not only {name}_dot?")
        broken = [b for b in self.found.broken if b.name == f"p_{name}"]
        if broken:
            return Finding(item, "wrong", "momentum_not_conserved",
                           f"{name} is cyclic, but its momentum is not conserved: "
                           f"{broken[0].reason}.", None,
                           hint=f"Does a load do virtual work along {name}?")
        return Finding(item, "correct", None, f"{name} is cyclic: L has no {name}, and "
                       f"p[{name}] is conserved.", None)

    def rate_of_change(self, F: sp.Expr) -> list:
        """dF/dt along the motion at the model's values (q_ddot from M q_ddot = f)."""
        model, points = self.model, self.valued
        q, q_dot, t = model.q, model.q_dot, model.time
        M, f = self.eom.mass_matrix, self.eom.forcing
        accelerations = eq.solve_at_points(sp.Matrix(M), -sp.Matrix(f), points)
        parts = [F.diff(x) for x in q] + [F.diff(v) for v in q_dot] + [F.diff(t)]
        rows = points.evaluate(parts)
        index = {s: k for k, s in enumerate(points.symbols)}
        rates = []
        with mpmath.workdps(eq.DIGITS):
            for values, row, a in zip(points.values, rows, accelerations, strict=True):
                if a is None:
                    continue
                n = len(q)
                total = row[2 * n] + sum(row[i] * values[index[q_dot[i]]] for i in range(n)) \
                    + sum(row[n + i] * a[i] for i in range(n))
                scale = max([mpmath.mpf(1), *(abs(x) for x in row)])
                rates.append(total / scale)
        return rates

    def quantity_finding(self, item: str, F: sp.Expr) -> Finding:
        if self.model.constraints:
            return Finding(item, "note", None, "not checked: a constrained model's conserved "
                           "quantities are not judged here.", None)
        if not (F.free_symbols & (set(self.model.q) | set(self.model.q_dot))):
            return Finding(item, "wrong", "not_conserved", f"{fmt(F)} has no state: it is "
                           "constant trivially; name a quantity of the motion.", None,
                           hint="Is it a function of the coordinates and rates?")
        rates = self.rate_of_change(F)
        if rates and all(abs(r) <= 1e-12 for r in rates):
            return Finding(item, "correct", None, f"{fmt(F)} is conserved: dF/dt = 0 along "
                           "every motion.", None)
        return self.not_conserved(item, F)

    def velocity_potential(self) -> bool:
        """Whether V holds a rate and T has no term without one (no drive)."""
        T, V, q_dot = self.eom.kinetic_energy, self.eom.potential_energy, self.model.q_dot
        at_rest = T.xreplace({v: 0 for v in q_dot})
        return any(V.has(v) for v in q_dot) and eq.zero(at_rest, self.points)

    def not_conserved(self, item: str, F: sp.Expr) -> Finding:
        eom, points = self.eom, self.points
        energy = eom.kinetic_energy + eom.potential_energy
        listed = "; ".join(f"{q.name} = {q.text}" for q in self.found) or "none"
        if not eq.zero(energy, points) and eq.constant_in_state(F / energy, points):
            kind = eom.invariant_kind
            if kind == InvariantKind.JACOBI_INTEGRAL and self.velocity_potential():
                # a magnetic field's V = -q v . A: its force does no work, h = T here
                why = ("V depends on the rates (a velocity-dependent potential: the Jacobi "
                       "integral h = q_dot . dL/dq_dot - L is conserved, not T + V)")
            elif kind == InvariantKind.JACOBI_INTEGRAL:
                why = ("the drive does work (T has terms without rates: the Jacobi integral "
                       "h = q_dot . dL/dq_dot - L is conserved, not T + V)")
            else:
                broken = [b.reason for b in self.found.broken if b.name == "h"]
                why = broken[0] if broken else "the loads do work"
            return Finding(item, "wrong", "energy_not_conserved",
                           f"T + V is not conserved here: {why}.", listed,
                           hint="Does anything (a drive, a load, explicit time) do work on "
                                "the system?")
        for name in self.names:
            ours = self.ours(name)
            if eq.zero(ours, points) or not eq.constant_in_state(F / ours, points):
                continue
            reason = self.cyclic_reason(name)
            if reason is not None:
                return Finding(item, "wrong", "not_cyclic",
                               f"this is the momentum of {name}, which is not cyclic: L "
                               f"depends on {name} through {reason}.", listed,
                               hint=f"Does L contain {name} itself, not only {name}_dot?")
            broken = [b.reason for b in self.found.broken if b.name == f"p_{name}"]
            if broken:
                return Finding(item, "wrong", "momentum_not_conserved",
                               f"this is the momentum of {name}, which is cyclic, but "
                               f"{broken[0]}.", listed,
                               hint=f"Does a load do virtual work along {name}?")
        for b in self.found.broken:  # a symmetry of L that a load breaks (a push on x1)
            if b.expression is not None and not eq.zero(b.expression, points) and \
                    eq.constant_in_state(F / b.expression, points):
                return Finding(item, "wrong", "momentum_not_conserved",
                               f"this is {fmt(b.expression)}, the quantity of a symmetry of L, "
                               f"but {b.reason}.", listed,
                               hint="Does a load do virtual work along the symmetry's "
                                    "direction?")
        return Finding(item, "wrong", "not_conserved",
                       f"{fmt(F)} changes along the motion (dF/dt != 0 by the equations of "
                       "motion).", listed,
                       hint="Is it dL/dq_dot of a coordinate L does not contain, or h = "
                            "q_dot . dL/dq_dot - L with no drive or load doing work?")

    # [routhian] ----------------------------------------------------------------------------

    def routhian_findings(self) -> list[Finding]:
        table = self.table("routhian", ("cyclic", "R", "L_R"))
        if "cyclic" not in table:
            raise self.fail("give the reduced coordinates: cyclic = [\"phi\"]", "routhian.cyclic")
        cyclic = self.names_list(table["cyclic"], "routhian.cyclic")
        for name in cyclic:
            finding = self.cyclic_finding(name)
            if finding.status != "correct":
                return [finding]
        try:
            reduced = routhian_model(self.eom, cyclic)
        except LagrangianError as error:
            return [Finding("R", "note", None, f"not checked: {error}", None)]
        L_R = reduced.kinetic_energy - reduced.potential_energy
        findings = []
        for key, ours, other in (("R", -L_R, "L_R"), ("L_R", L_R, "R")):
            if key not in table:
                continue
            yours = self.expression(table[key], f"routhian.{key}")
            findings.append(self.routhian_finding(key, yours, ours, other, reduced))
        return findings

    def routhian_finding(self, key, yours, ours, other, reduced) -> Finding:
        points = self.points
        expected = fmt(eq.display(ours))
        if eq.identical(yours, ours, points) or eq.constant_in_state(yours - ours, points):
            return Finding(key, "correct", None, f"{key} matches (R = sum p q_dot - L, "
                           "L_R = -R).", None)
        if eq.identical(yours, -ours, points) or eq.constant_in_state(yours + ours, points):
            return Finding(key, "wrong", "routhian_sign",
                           f"yours is {other}, of the opposite sign: here R = sum p_k q_dot_k - "
                           "L (Goldstein, Landau) and the reduced Lagrangian is L_R = -R.",
                           expected, hint="Which sign convention: R = p q_dot - L, or its "
                                          "negative L_R?")
        rest = dict.fromkeys((c.velocity for c in reduced.coordinates), sp.S.Zero)
        if eq.zero((yours - ours) - (yours - ours).xreplace(rest), points):
            return Finding(key, "wrong", "effective_potential",
                           "the terms with rates are right; the terms without them (the "
                           "effective potential, with p^2/(2 I) of each cyclic momentum) "
                           f"differ by {fmt(eq.display((yours - ours).xreplace(rest)))}.",
                           expected, hint="Did you eliminate the cyclic rate through its "
                                          "momentum, p = dL/dq_dot, before forming R?")
        return Finding(key, "wrong", "routhian_wrong",
                       f"{key} differs from ours by {fmt(eq.display(yours - ours))}.", expected,
                       hint="Did you write the cyclic rate through its momentum and form "
                            "R = p q_dot - L?")

    # [hamiltonian] -------------------------------------------------------------------------

    def hamiltonian_findings(self) -> list[Finding]:
        table = self.table("hamiltonian", ("H",))
        if "H" not in table:
            raise self.fail("give H = \"...\" in the coordinates and p_<coordinate>",
                            "hamiltonian.H")
        yours = self.expression(table["H"], "hamiltonian.H")
        try:
            hamiltonian = hamiltonian_of(self.eom)
            ours = hamiltonian.H
        except LagrangianError as error:
            return [Finding("H", "note", None, f"not checked: {error}", None)]
        expected = fmt(eq.display(ours)) if eq.is_small(ours) else fmt(ours)
        rates = sorted(str(v) for v in yours.free_symbols & set(self.model.q_dot))
        if rates:
            return [Finding("H", "wrong", "hamiltonian_in_velocities",
                            f"H is a function of q and p: yours has {', '.join(rates)}; write "
                            "each rate through the momenta (p = dL/dq_dot, q_dot = M^-1 p).",
                            expected, hint="Is H written in the momenta p, not the rates?")]
        points = self.points
        if eq.identical(yours, ours, points) or eq.constant_in_state(yours - ours, points):
            return [Finding("H", "correct", None, "H matches.", None)]
        p = sp.Matrix(self.momenta)
        naive = (p.T * sp.Matrix(hamiltonian.inertia) * p)[0, 0] / 2 - hamiltonian.rest
        if eq.identical(yours, naive, points):
            return [Finding("H", "wrong", "hamiltonian_inverse",
                            "your kinetic part is 1/2 p^T M p; it is 1/2 p^T M^-1 p (q_dot = "
                            "M^-1 p: divide by the inertia, do not multiply).", expected,
                            hint="Did you invert p = M q_dot for the rates?")]
        return [Finding("H", "wrong", "hamiltonian_wrong",
                        f"H differs from ours by {fmt(eq.display(yours - ours))}; H = "
                        "p . q_dot - L with q_dot written through p.", expected,
                        hint="Is H = p . q_dot - L, with every rate written through p?")]


__all__ = ["MECHANICS_CODES", "check_mechanics"]
