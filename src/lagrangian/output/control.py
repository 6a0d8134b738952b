"""A controller's summary line for ``simulate --control`` (its JSON is the controller's
``summary()``), and the model's own [control] laws (``--control model``): line and JSON."""

from __future__ import annotations

from ..model.model import Model
from ..model.printing import format_expression, shown_expression


def controller_text(controller) -> str:
    """One line: what the controller drives and its closed-loop eigenvalues (1/s)."""
    summary = controller.summary()
    drives = ", ".join(summary.get("inputs") or summary.get("coordinates") or [])
    values = ", ".join(_complex(re, im) for re, im in summary["closed_loop_eigenvalues"])
    kind = "LQR" if "K" in summary else "computed torque"
    return f"controller: {kind} on {drives}; closed-loop eigenvalues (1/s): {values}"


def _complex(re: float, im: float) -> str:
    return f"{re:.4g}" if im == 0 else f"{re:.4g}{im:+.4g}j"


def law_summary(model: Model) -> dict:
    """JSON-ready: the inputs the model's [control] laws drive and each law as printed."""
    return {"inputs": [name for name, _ in model.control],
            "laws": {name: format_expression(law) for name, law in model.control}}


def law_text(model: Model) -> str:
    """One line: the laws of the model's [control] table, compiled with its equations."""
    laws = "; ".join(f"{name} = {shown_expression(law)}" for name, law in model.control)
    return f"controller: the model's [control] laws, compiled with its equations: {laws}"
