"""System methods that hand a model to other code and tools: standalone C99 (to_c), CasADi
(to_casadi), opty (to_opty) and an FMI 2.0 FMU, Model Exchange and Co-Simulation (to_fmu,
output/fmu.py); docs/codegen.md and docs/bridges.md."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError, did_you_mean

if TYPE_CHECKING:  # imported by the methods that use them (issue 38)
    from ..dynamics.standalone.standalone import StandaloneSource


def fmu_of(system, path: str | Path, parameters: Mapping[str, float] | None = None) -> Path:
    """Write ``path`` (.fmu): FMI 2.0 Model Exchange and Co-Simulation, the generated C compiled
    for this platform; the states q, q_dot as outputs, the parameters tunable (their values,
    SI, with ``parameters`` overriding the model's), a generalized force Q_<coordinate> per
    coordinate as an input. Unconstrained models whose equations do not depend on time (as System.to_c)."""
    from ..output.fmu import PREFIX, fmu_bytes, model_identifier, write_fmu

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


class ExportMethods:
    """to_c(), to_casadi(), to_opty() and to_fmu() of a System."""

    # -- standalone C for a controller -----------------------------------------------------------

    def to_c(self, prefix: str | None = None, parameters: Mapping[str, float] | None = None
             ) -> StandaloneSource:
        """Standalone C99 (header and source, libm only, no allocation) of M(q), the bias
        C q_dot + g, g(q), inverse and forward dynamics and the energies (SI units);
        ``prefix`` names the functions (default: from the model's name), ``parameters`` override
        the model's values compiled in as defaults; a [control] table's laws as <prefix>_control
        and <prefix>_control_forces; a robot's frames, and its ball and free joints (q of
        <PREFIX>_NQ numbers, v of <PREFIX>_N). Write it with
        ``lagrangian.output.files.write_c(code, dir)``."""
        from ..compile.codegen import CodegenError
        from ..dynamics.standalone.standalone import c_prefix, standalone_for
        from ..simulation.control import input_columns  # B of a [control] table's inputs

        if prefix is not None and c_prefix(prefix) != prefix:
            raise InputError(f"{prefix!r} is not a C identifier (lower-case ASCII letters, digits "
                             "and _, a letter first, at most 40)", field="prefix")
        values = dict(self.parameters)
        for name, value in dict(parameters or {}).items():
            if name not in values:
                raise InputError(f"'{name}' is not a parameter of this model"
                                 f"{did_you_mean(name, values)}", field="parameters")
            values[name] = float(value)
        missing = [k for k, v in values.items() if v is None]
        if missing:
            raise InputError(f"parameters without a value: {', '.join(missing)} (give them with "
                             "parameters=...)", field="parameters")
        system = self if not parameters else self.with_parameters(**dict(parameters))
        try:
            return standalone_for(system.model, system.equations_of_motion, values, prefix,
                                  columns=input_columns)
        except CodegenError as exc:
            raise InputError(f"cannot write C: {exc}", field="lang") from None

    # -- bridges to other tools ------------------------------------------------------------------

    def to_casadi(self, inputs: Sequence[str] = (), parameters: Mapping[str, float] | None = None):
        """CasADi Functions built node by node from the derived equations (SI units, x = [q;
        q_dot]): ``rhs(x, u)``, ``mass_matrix(q)``, ``forcing(q, q_dot, u)`` and, with
        constraints, ``constraints(q, q_dot)``; ``inputs`` name the entries of u as in
        ``linearize(inputs=...)``. A robot read from URDF or MJCF gets them from its tree: the
        numpy reference's recursions over casadi SX (nothing derived; every joint kind; inputs:
        the joints' velocity numbers or their tau_<joint>). Needs the extra [casadi]
        (docs/bridges.md)."""
        from ..compile.casadi_functions import casadi_functions
        from ..compile.functions import refuse_large_chain

        # a robot's tree (URDF, MJCF, RobotBuilder), also one whose joints have no source
        # name of their own (an MJCF ball joint's quaternion): our dynamics' q and v
        if self._model.kinematic_tree is not None:
            from ..dynamics.standalone.casadi_tree import tree_casadi_functions

            return tree_casadi_functions(self._model, inputs, parameters)
        refuse_large_chain(self.model)
        return casadi_functions(self.equations_of_motion(), inputs, parameters)

    def to_opty(self, inputs: Sequence[str] = (), parameters: Mapping[str, float] | None = None):
        """opty's equations of an unconstrained model (sympy, opty itself not needed):
        ``eom`` = 0 in x = [q(t); u(t)] and x', ``states``, ``specified`` r_<input>(t) (named
        as for ``linearize(inputs=...)``), ``parameters`` for known_parameter_map and
        ``time``, for ``opty.Problem(obj, grad, eom, states, nodes, interval, ...)``."""
        from ..compile.functions import refuse_large_chain
        from ..compile.opty_equations import opty_equations

        refuse_large_chain(self.model)
        return opty_equations(self.equations_of_motion(), inputs, parameters)

    def to_fmu(self, path: str | Path, parameters: Mapping[str, float] | None = None) -> Path:
        """Write an FMI 2.0 FMU (.fmu: Model Exchange and Co-Simulation) of the model: its
        standalone C compiled for this platform, q and q_dot as outputs, the parameters
        tunable (SI; ``parameters`` override the model's values), Q_<coordinate> inputs
        (docs/bridges.md)."""
        return fmu_of(self, path, parameters)


__all__ = ["ExportMethods", "fmu_of"]
