"""System.to_fmu: an FMI 2.0 FMU (Model Exchange and Co-Simulation) of a model (output/fmu.py)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from ..errors import InputError
from ..output.fmu import PREFIX, fmu_bytes, model_identifier, write_fmu


def to_fmu(system, path: str | Path, parameters: Mapping[str, float] | None = None) -> Path:
    """Write ``path`` (.fmu): FMI 2.0 Model Exchange and Co-Simulation, the generated C compiled
    for this platform; the states q, q_dot as outputs, the parameters tunable (their values,
    SI, with ``parameters`` overriding the model's), a generalized force Q_<coordinate> per
    coordinate as an input. Unconstrained models whose equations do not depend on time (as System.to_c)."""
    path = Path(path)
    if path.suffix.lower() != ".fmu":
        raise InputError(f"{path} does not end in .fmu", field="fmu")
    model = system.model
    if getattr(model, "kinematic_tree", None) is not None and model.kinematic_tree.floating_base:
        raise InputError("a floating base cannot be exported as an FMU yet", field="fmu")
    if model.constraints:
        raise InputError("an FMU covers models without constraints (yet)", field="fmu")
    if model.time in set().union(*(f.free_symbols for f in system.equations_of_motion().forcing)):
        raise InputError("the equations depend on time t explicitly: not in an FMU yet",
                         field="fmu")
    code = system.to_c(prefix=PREFIX, parameters=parameters)
    values = dict(system.parameters)
    values.update({k: float(v) for k, v in dict(parameters or {}).items()})
    coordinates = [c.name for c in model.coordinates]
    start = [float(c.initial or 0.0) for c in model.coordinates] + \
        [float(c.rate or 0.0) for c in model.coordinates]
    data = fmu_bytes(code, model_identifier(path), name=model.name,
                     description=model.description or "",
                     coordinates=coordinates, units=[c.unit for c in model.coordinates],
                     parameters=[(p.name, values[p.name], p.unit) for p in model.parameters],
                     initial=start)
    return write_fmu(data, path)


__all__ = ["to_fmu"]
