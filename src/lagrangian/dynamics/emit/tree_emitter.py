"""Straight-line C for the tree algorithms: an emitter of named terms (numbers folded,
common terms shared, zeros and ones dropped) and the layout of a tree's inputs."""

from __future__ import annotations

import numpy as np

from ...errors import ModelError
from ...model.tree import KinematicTree

Term = float | str  # a number, or the C name of a value computed before
# coordinates up to which batches run several states per vector operation: a 16-body tree
# asked for with kernel="unrolled", a floating base's six included (Solo12's cold build
# 4.1 -> 4.5 s; its M, bias and ID batches 1.5-2.7x)
VECTOR_LIMIT = 24


class _Emitter:
    """Straight-line C with constants folded and equal operations computed once (value
    numbering): x*0, x*1, x+0 vanish, so a z axis or an identity placement costs nothing."""

    def __init__(self):
        self.lines: list[tuple[str, str, tuple[str, ...]]] = []
        self.memo: dict[tuple, str] = {}
        self.negated: dict[str, str] = {}  # name of -x -> name of x

    def _new(self, key: tuple, text: str, deps: tuple) -> str:
        hit = self.memo.get(key)
        if hit is not None:
            return hit
        name = f"t{len(self.lines)}"
        self.lines.append((name, text, tuple(d for d in deps if isinstance(d, str))))
        self.memo[key] = name
        return name

    @staticmethod
    def text(x: Term) -> str:
        if isinstance(x, str):
            return x
        return repr(float(x)) if x >= 0 else f"({float(x)!r})"

    def neg(self, a: Term) -> Term:
        if not isinstance(a, str):
            return -a + 0.0
        if a in self.negated:
            return self.negated[a]
        name = self._new(("-", a), f"-{a}", (a,))
        self.negated[name] = a
        return name

    def add(self, a: Term, b: Term) -> Term:
        if not isinstance(a, str) and not isinstance(b, str):
            return a + b
        if not isinstance(a, str) and a == 0:
            return b
        if not isinstance(b, str) and b == 0:
            return a
        if isinstance(b, str) and b in self.negated:
            return self.sub(a, self.negated[b])
        if isinstance(a, str) and a in self.negated:
            return self.sub(b, self.negated[a])
        x, y = sorted((a, b), key=repr)
        return self._new(("+", x, y), f"{self.text(x)} + {self.text(y)}", (x, y))

    def sub(self, a: Term, b: Term) -> Term:
        if not isinstance(a, str) and not isinstance(b, str):
            return a - b
        if not isinstance(b, str) and b == 0:
            return a
        if not isinstance(a, str) and a == 0:
            return self.neg(b)
        if a == b:
            return 0.0
        if isinstance(b, str) and b in self.negated:
            return self.add(a, self.negated[b])
        return self._new(("-", a, b), f"{self.text(a)} - {self.text(b)}", (a, b))

    def mul(self, a: Term, b: Term) -> Term:
        if not isinstance(a, str) and not isinstance(b, str):
            return a * b
        if not isinstance(a, str):
            a, b = b, a  # the constant second
        if not isinstance(b, str):
            if b == 0:
                return 0.0
            if b == 1:
                return a
            if b == -1:
                return self.neg(a)
            if a in self.negated:
                return self.mul(self.negated[a], -b)
            return self._new(("*", a, b), f"{a} * {self.text(b)}", (a,))
        if a in self.negated:
            return self.neg(self.mul(self.negated[a], b))
        if b in self.negated:
            return self.neg(self.mul(a, self.negated[b]))
        x, y = sorted((a, b))
        return self._new(("*", x, y), f"{x} * {y}", (x, y))

    def div(self, a: Term, b: Term) -> Term:
        if not isinstance(b, str):
            if b == 0:
                raise ZeroDivisionError("a joint moves nothing (massless subtree)")
            return self.mul(a, 1.0 / b)
        if not isinstance(a, str) and a == 0:
            return 0.0
        return self._new(("/", a, b), f"{self.text(a)} / {b}", (a, b))

    def sincos(self, a: Term) -> tuple[Term, Term]:
        """sin a and cos a from one lg_sincos call (the C preamble's inline kernels)."""
        if not isinstance(a, str):
            return float(np.sin(a)), float(np.cos(a))
        pair = self._new(("sincos", a), f"lg_sincos({a}, &@s, &@c)", (a,))
        names = []
        for part in "sc":
            name = f"{pair}{part}"
            if ("part", name) not in self.memo:
                self.lines.append((name, None, (pair,)))
                self.memo[("part", name)] = name
            names.append(name)
        return names[0], names[1]

    def call(self, function: str, a: Term) -> Term:
        if not isinstance(a, str):
            value = float(getattr(np, function)(a)) if function != "sqrt" or a >= 0 else np.nan
            if not np.isfinite(value):
                raise ZeroDivisionError(f"{function}({a})")
            return value
        return self._new((function, a), f"{function}({a})", (a,))

    # -- 3-vectors and 3x3 matrices of terms ----------------------------------------------------

    def sum(self, terms) -> Term:
        total: Term = 0.0
        for t in terms:
            total = self.add(total, t)
        return total

    def dot(self, a, b) -> Term:
        return self.sum(self.mul(x, y) for x, y in zip(a, b, strict=True))

    def vadd(self, a, b):
        return [self.add(x, y) for x, y in zip(a, b, strict=True)]

    def scale(self, s: Term, a):
        return [self.mul(s, x) for x in a]

    def cross(self, a, b):
        return [self.sub(self.mul(a[1], b[2]), self.mul(a[2], b[1])),
                self.sub(self.mul(a[2], b[0]), self.mul(a[0], b[2])),
                self.sub(self.mul(a[0], b[1]), self.mul(a[1], b[0]))]

    def apply(self, R, x):
        return [self.dot(row, x) for row in R]

    def apply_transpose(self, R, x):
        return [self.dot([R[0][i], R[1][i], R[2][i]], x) for i in range(3)]

    def matmul(self, A, B):
        return [[self.dot(A[i], [B[0][j], B[1][j], B[2][j]]) for j in range(3)]
                for i in range(3)]

    def count(self, outputs: list[tuple[str, Term]]) -> int:
        """How many operations ``body(outputs)`` performs (its statements)."""
        return self.body(outputs).count(";")

    def body(self, outputs: list[tuple[str, Term]], indent: str = "    ",
             vector: bool = False) -> str:
        """The C statements computing ``target = term`` for each output (dead temporaries
        dropped). ``vector``: values that depend on q, v, a or tau are lg_v4 (LG_LANES states),
        the others (parameters, numbers) stay double."""
        live = {t for _, t in outputs if isinstance(t, str)}
        keep = []
        for name, text, deps in reversed(self.lines):
            if name in live:
                keep.append((name, text, deps))
                live.update(deps)
        lanes: set[str] = set()
        statements = []
        for name, text, deps in reversed(keep):
            if vector and any(d in lanes or d.split("[")[0] in _STATE for d in deps):
                lanes.add(name)
            kind = "lg_v4" if name in lanes else "double"
            if text is None:  # one of a sincos pair, declared with it
                continue
            if text.startswith("lg_sincos("):
                call = "lg_vsincos(" if name in lanes else "lg_sincos("
                statements.append(f"{indent}{kind} {name}s, {name}c; "
                                  + text.replace("lg_sincos(", call).replace("@s", f"{name}s")
                                  .replace("@c", f"{name}c") + ";")
            elif vector and name in lanes:
                statements.append(f"{indent}const lg_v4 {name} = "
                                  + text.replace("sqrt(", "lg_vsqrt(") + ";")
            else:
                statements.append(f"{indent}const double {name} = {text};")
        for target, term in outputs:
            value = self.text(term)
            if vector and not (term in lanes or value.split("[")[0] in _STATE):
                value = f"LG_V4({value})"
            statements.append(f"{indent}{target} = {value};")
        return "\n".join(statements)


_STATE = {"q", "v", "a", "tau"}  # the inputs that differ between the states of one vector


class _Layout:
    """Where each input of the generated code lives: q[i], v[i], a[i], p[k]."""

    def __init__(self, tree: KinematicTree, parameters: tuple[str, ...]):
        self.tree = tree
        index = {name: k for k, name in enumerate(parameters)}
        missing = [name for name in (tree.gravity_parameter, *tree.actuators)
                   if name is not None and name not in index]
        if missing:
            raise ModelError(f"the tree's parameters {missing} are not the model's")
        # no gravity, or no force on a coordinate: the number 0, folded away
        self.gravity = 0.0 if tree.gravity_parameter is None else \
            f"p[{index[tree.gravity_parameter]}]"
        self.actuators = [0.0 if name is None else f"p[{index[name]}]"
                          for name in tree.actuators]
        self.n = tree.nv  # v's numbers (3 per ball joint, 6 per free flyer)
        self.nq = tree.nq  # q's (4 per ball joint, 7 per free flyer)


def _cholesky_solve(E: _Emitter, mass: dict, rhs: list) -> list:
    """x with M x = rhs by M = L L^T, straight-line (zeros of M, e.g. between two branches of
    the tree, fold away); M given by its lower triangle."""
    n = len(rhs)
    L: dict = {}
    inverse = []
    for j in range(n):
        d = E.sub(mass.get((j, j), 0.0), E.sum(E.mul(L[j, k], L[j, k]) for k in range(j)))
        inverse.append(E.div(1.0, E.call("sqrt", d)))
        for i in range(j + 1, n):
            e = E.sub(mass.get((i, j), 0.0), E.sum(E.mul(L[i, k], L[j, k]) for k in range(j)))
            L[i, j] = E.mul(e, inverse[j])
        L[j, j] = E.div(1.0, inverse[j])
    y = []
    for i in range(n):
        y.append(E.mul(E.sub(rhs[i], E.sum(E.mul(L[i, k], y[k]) for k in range(i))), inverse[i]))
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = E.mul(E.sub(y[i], E.sum(E.mul(L[k, i], x[k]) for k in range(i + 1, n))),
                     inverse[i])
    return x
