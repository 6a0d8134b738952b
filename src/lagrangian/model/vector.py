"""A vector in the model's expressions: three sympy expressions (x, y, z; z is 0 in the plane).
Apart from model.py, so that the modules model.py's dataclasses hold (rotations.py, contacts.py)
name it without importing them."""

from __future__ import annotations

import sympy as sp

Vector = tuple[sp.Expr, sp.Expr, sp.Expr]
