"""The `speeds` report: the reduced equations M q'' + v C1 q' + (g K0 + v^2 K2) q = f, the
eigenvalues against speed with the speeds where their real parts cross zero, and its plot."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.speed_form import SpeedForm, SpeedSweep
from ..errors import ModelError
from ..kinds import CrossingKind
from .files import atomic_write

PLOT_DPI = 100
_NAMES = {CrossingKind.OSCILLATORY: "oscillatory (a complex pair; the weave of a bicycle)",
          CrossingKind.REAL: "real (the capsize of a bicycle)"}


def _rows(matrix: np.ndarray) -> list[list[float]]:
    return [[float(v) + 0.0 for v in row] for row in np.asarray(matrix, dtype=float)]


def speed_form_document(model: str, form: SpeedForm, sweep: SpeedSweep) -> dict[str, Any]:
    """The `speeds --json` document (matrices by rows, SI units; eigenvalues as [re, im])."""
    return {
        "model": model,
        "form": "M q'' + (C0 + v C1) q' + (g K0 + v K1 + v^2 K2) q = f",
        "coordinates": list(form.coordinates),
        "speed": form.speed,
        "rates": dict(form.rates),
        "about": dict(form.about),
        "g": form.g,
        "M": _rows(form.M), "C1": _rows(form.C1), "K0": _rows(form.K0), "K2": _rows(form.K2),
        "C0": _rows(form.C0), "K1": _rows(form.K1),
        "fit_error": form.fit_error,
        "speeds": [float(v) for v in sweep.speeds],
        "eigenvalues": [[[float(z.real), float(z.imag)] for z in row] for row in sweep.eigenvalues],
        "crossings": [{"speed": c.speed, "kind": c.kind, "frequency": c.frequency,
                       "stabilizing": c.stabilizing} for c in sweep.crossings],
        "stable": [list(interval) for interval in sweep.stable],
    }


def _matrix(name: str, matrix: np.ndarray, coordinates) -> list[str]:
    width = max(12, *(len(c) for c in coordinates))
    lines = [f"{name} =", "  " + " " * width + "".join(f"{c:>22}" for c in coordinates)]
    for c, row in zip(coordinates, np.asarray(matrix), strict=True):
        lines.append(f"  {c:>{width}}" + "".join(f"{float(v) + 0.0:>22.14g}" for v in row))
    return lines


def speed_form_text(model: str, form: SpeedForm, sweep: SpeedSweep) -> str:
    title = f"Lean-steer form of {model}" if form.coordinates == ("phi", "delta") \
        else f"Reduced equations of {model}"
    lines = [title, "=" * len(title),
             f"M q'' + {form.speed} C1 q' + (g K0 + {form.speed}^2 K2) q = f,  q = "
             f"({', '.join(form.coordinates)}),  f = their generalized forces, g = {form.g:g}",
             "about steady motion with " + ", ".join(f"{k} = {v}" for k, v in form.rates.items()),
             ""]
    for name in ("M", "C1", "K0", "K2"):
        lines += _matrix(name, getattr(form, name), form.coordinates)
    for name in ("C0", "K1"):
        matrix = getattr(form, name)
        if np.any(matrix != 0):
            lines += [f"(outside the form: {name} is not zero)"]
            lines += _matrix(name, matrix, form.coordinates)
    lines += ["", f"Eigenvalues (1/s) against {form.speed}:"]
    step = max(1, len(sweep.speeds) // 11)
    for v, row in zip(sweep.speeds[::step], sweep.eigenvalues[::step], strict=True):
        values = "  ".join(f"{z.real:+.6f}{z.imag:+.6f}j" if abs(z.imag) > 1e-9
                           else f"{z.real:+.6f}" for z in row)
        lines.append(f"  {v:8.4g}:  {values}")
    lines.append("")
    if not sweep.crossings:
        lines.append("No eigenvalue's real part crosses zero in this range.")
    for c in sweep.crossings:
        turn = "stable above" if c.stabilizing else "unstable above"
        extra = f", {c.frequency:.6g} rad/s" if c.kind == CrossingKind.OSCILLATORY else ""
        lines.append(f"Re = 0 at {form.speed} = {c.speed:.10g}: {_NAMES[c.kind]}{extra}; "
                     f"{turn}")
    for lo, hi in sweep.stable:
        lines.append(f"Stable for {lo:.10g} < {form.speed} < {hi:.10g}")
    if sweep.crossings and not sweep.stable:
        lines.append("Stable nowhere in this range.")
    return "\n".join(lines) + "\n"


def _stable_at(values: np.ndarray) -> bool:
    scale = max(float(np.abs(values).max(initial=0.0)), 1e-300)
    return not bool(np.any(values.real > 1e-9 * scale))


def chosen_speeds_document(form: SpeedForm, speeds) -> list[dict[str, Any]]:
    """The `at` entries of `speeds --json`: each chosen speed's eigenvalues ([re, im], 1/s,
    largest real part first) and whether none grows."""
    out = []
    for v in speeds:
        values = form.eigenvalues(float(v))
        out.append({"speed": float(v),
                    "eigenvalues": [[float(z.real), float(z.imag)] for z in values],
                    "stable": _stable_at(values)})
    return out


def chosen_speeds_text(form: SpeedForm, speeds) -> str:
    lines = ["", f"Eigenvalues (1/s) at the chosen speeds {form.speed}:"]
    for v in speeds:
        values = form.eigenvalues(float(v))
        text = "  ".join(f"{z.real:+.9g}{z.imag:+.9g}j" if abs(z.imag) > 1e-9
                         else f"{z.real:+.9g}" for z in values)
        lines.append(f"  {float(v):8.4g}:  {text}   "
                     f"({'stable' if _stable_at(values) else 'unstable'})")
    return "\n".join(lines) + "\n"


def speed_sweep_figure(form: SpeedForm, sweep: SpeedSweep):
    """Real parts (solid) and imaginary parts (dotted) of the eigenvalues against speed, with
    the crossings marked."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.0, 4.5), dpi=PLOT_DPI, layout="constrained")
    axes = figure.subplots()
    speeds, values = sweep.speeds, sweep.eigenvalues
    axes.plot(speeds, values.real, ".", color="tab:blue", markersize=3)
    axes.plot(speeds, np.abs(values.imag), ".", color="tab:orange", markersize=2)
    axes.axhline(0.0, color="black", linewidth=0.8)
    for lo, hi in sweep.stable:
        axes.axvspan(lo, hi, color="tab:green", alpha=0.12)
    for c in sweep.crossings:
        label = "weave" if c.kind == CrossingKind.OSCILLATORY else "capsize"
        axes.axvline(c.speed, color="gray", linestyle="--", linewidth=0.8)
        axes.annotate(f"{label} {c.speed:.3f}", (c.speed, 0), textcoords="offset points",
                      xytext=(3, 8), fontsize=8)
    axes.set_xlabel(f"{form.speed} (m/s)")
    axes.set_ylabel("eigenvalue (1/s): real (blue), |imaginary| (orange)")
    axes.set_ylim(-10, 10)
    axes.set_title(f"Eigenvalues of ({', '.join(form.coordinates)}) against speed")
    return figure


def write_speed_plot(form: SpeedForm, sweep: SpeedSweep, path: str | Path, *,
                     protect: tuple[Path, ...] = ()) -> Path:
    """Draw the eigenvalues against speed (PNG, SVG or PDF by the suffix), atomically."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in ("png", "svg", "pdf"):
        raise ModelError(f"cannot write {path}: use a .png, .svg or .pdf file name", field="plot")
    buffer = io.BytesIO()
    speed_sweep_figure(form, sweep).savefig(buffer, format=suffix, dpi=PLOT_DPI)
    return atomic_write(path, buffer.getvalue(), protect=protect)
