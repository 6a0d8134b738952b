"""A controller's summary line for ``simulate --control`` (its JSON is the controller's
``summary()``)."""

from __future__ import annotations


def controller_text(controller) -> str:
    """One line: what the controller drives and its closed-loop eigenvalues (1/s)."""
    summary = controller.summary()
    drives = ", ".join(summary.get("inputs") or summary.get("coordinates") or [])
    values = ", ".join(_complex(re, im) for re, im in summary["closed_loop_eigenvalues"])
    kind = "LQR" if "K" in summary else "computed torque"
    return f"controller: {kind} on {drives}; closed-loop eigenvalues (1/s): {values}"


def _complex(re: float, im: float) -> str:
    return f"{re:.4g}" if im == 0 else f"{re:.4g}{im:+.4g}j"
