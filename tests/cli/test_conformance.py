"""The conformance matrix (issue 21): every command on every built-in example and on a set of
model kinds (massless, constant-coefficient, constrained, nonholonomic, 3D, URDF,
time-dependent, steady motion). Each cell either exits 0 with results that pass a sanity check
(eigenpairs satisfy their own equations to 1e-9 relative, constraints hold, the JSON has its
documented keys) or exits 2 with exactly one line ``error: ...`` on stderr: never a traceback,
never exit 0 with nothing computed.

Every cell is one test id, ``test_cell[COMMAND-MODEL]``. The cells run in-process (the ``cli``
fixture); the costly ones (whipple_bicycle, compiled simulations, the sweeps) are marked slow.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

from lagrangian.model.examples import example_names, example_path

MODELS_DIR = Path(__file__).parent / "conformance_models"
EXAMPLES = example_names()

# model kinds that no built-in example covers, as small model files (fixtures)
FIXTURES = {
    "symbol_free": MODELS_DIR / "symbol_free.toml",        # constant coefficients, no symbols
    "massless_crank": MODELS_DIR / "massless_crank.toml",  # massless, constrained, with loads
    "coin_steady": MODELS_DIR / "coin_steady.toml",        # nonholonomic 3D with a [steady] table
    "slider_arm": MODELS_DIR / "slider_arm.urdf",          # URDF: prismatic, fixed, continuous
}
# the kinds the built-in examples cover: constrained (cartesian_pendulum, four_bar,
# slider_crank), nonholonomic (rolling_coin, whipple_bicycle), 3D (heavy_top, sleeping_top,
# torque_free_body), URDF (two_link_arm), time-dependent (support_pendulum, bead_on_hoop),
# massless (virtual_work_link is massless as far as simulate is concerned: see its cells),
# constant-coefficient (two_mass, damped_oscillator), steady motion (whipple_bicycle)

MODELS = {name: str(example_path(name)) for name in EXAMPLES} | {
    name: str(path) for name, path in FIXTURES.items()}


def _table(name: str) -> dict:
    path = Path(MODELS[name])
    return tomllib.loads(path.read_text(encoding="utf-8")) if path.suffix == ".toml" else {}


# The parameter each model's 3-point sweep varies (one the equations contain); a model without
# parameters varies an initial value through `--compute simulate`.
SWEEP_VARY = {
    "atwood": "m1", "bead_on_hoop": "Omega", "cart_pendulum": "l", "cartesian_pendulum": "L",
    "charged_particle": "B", "damped_oscillator": "k", "double_pendulum": "l2", "four_bar": "k",
    "heavy_top": "l", "ladder_pendulum": "L", "ladder_spring_mass": "k",
    "ladder_vertical_force": "L", "pendulum": "L", "rolling_coin": "r", "rolling_cylinder": "R",
    "rolling_disk": "R", "sleeping_top": "l", "slider_crank": "k", "support_pendulum": "L",
    "torque_free_body": "I1", "two_mass": "k", "virtual_work_link": "L", "whipple_bicycle": "v",
    "two_link_arm": "g", "massless_crank": "l", "coin_steady": "r", "slider_arm": "g",
    "symbol_free": None, "bouncing_ball": "e", "rimless_wheel": "gamma",
    "compass_gait": "gamma", "falling_rod": "e",
}

# statics where there are loads: the configuration and the load magnitudes found
STATICS = {
    "cart_pendulum": ["--at", "x=0,theta=0", "--solve-for", "F"],
    "ladder_vertical_force": ["--at", "theta=30deg", "--solve-for", "F"],
    "virtual_work_link": ["--at", "theta=30deg", "--solve-for", "F"],
    "massless_crank": ["--at", "theta=40deg", "--solve-for", "P"],
    "two_link_arm": ["--at", "shoulder=0.3,elbow=0.2", "--solve-for", "tau_shoulder,tau_elbow"],
    "slider_arm": ["--at", "slide=0.1,hinge=0.4", "--solve-for", "tau_slide,tau_hinge"],
}

# modes about steady motion: the models with a [steady] table (its rates), and the examples whose
# descriptions name a steady motion
STEADY = {
    "sleeping_top": ["--about", "a=0,b=0", "--steady", "psi_dot=60"],
    "rolling_coin": ["--about", "lean=0", "--steady", "spin_dot=4,x_dot=1.2"],
}
for _name in MODELS:
    _steady = _table(_name).get("steady")
    if _steady:
        _rates = ",".join(f"{k}={v}" for k, v in _steady["rates"].items())
        _about = _steady.get("about") or {c: 0 for c in _steady.get("keep", [])}
        STEADY[_name] = ["--steady", _rates] + (
            ["--about", ",".join(f"{k}={v}" for k, v in _about.items())] if _about else [])

COMMANDS = ["derive", "forces", "equilibria", "modes", "modes-steady", "speeds", "statics",
            "simulate", "check", "crosscheck", "units", "dynamics", "codegen", "sweep"]

# Cells that fail today because of a known defect: xfail(strict=False) with the defect named,
# so a fix turns them into XPASS, not a failure. None are known now.
KNOWN: dict[tuple[str, str], str] = {}

SLOW_MODELS = {"whipple_bicycle"}
SLOW_COMMANDS = {"simulate", "sweep", "crosscheck", "codegen"}


def _applies(command: str, name: str) -> bool:
    if command == "modes-steady":
        return name in STEADY
    if command == "speeds":
        return bool(_table(name).get("steady"))
    if command == "statics":
        return name in STATICS
    return True


def _cells():
    for name in MODELS:
        for command in COMMANDS:
            if not _applies(command, name):
                continue
            marks = []
            if name in SLOW_MODELS or command in SLOW_COMMANDS:
                marks.append(pytest.mark.slow)
            if (command, name) in KNOWN:
                marks.append(pytest.mark.xfail(strict=False, reason=KNOWN[command, name]))
            yield pytest.param(command, name, id=f"{command}-{name}", marks=marks)


@pytest.fixture(scope="module")
def scheduler():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=1,
                            dashboard_address=":0") as client:
        yield client.scheduler.address


# -- the sanity checks ------------------------------------------------------------------------

def _finite(value) -> bool:
    """Every number in a JSON value is finite (None allowed: e.g. the period of a static mode)."""
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, list):
        return all(_finite(v) for v in value)
    if isinstance(value, float):
        return math.isfinite(value)
    return True


def _has(document: dict, *keys: str) -> None:
    missing = [key for key in keys if key not in document]
    assert not missing, f"JSON without its documented keys {missing}: {sorted(document)}"


def mode_constraints(cli, model: str, document: dict) -> dict | None:
    """The model's constraints linearized at the modes' point, when the modes are given in all
    the coordinates (a nonholonomic model): A = Phi_q or the velocity Jacobian at q0, and
    B = d(A(q) q0_dot)/dq for the steady rates q0_dot."""
    import sympy as sp

    code, out, _ = cli("derive", model, "--json")
    derived = json.loads(out) if code == 0 else {}
    found = derived.get("constraints")
    if not found or list(derived["coordinates"]) != list(document["coordinates"]):
        return None
    names = derived["coordinates"]
    q = [sp.Symbol(name) for name in names]
    symbols = {name: sp.Symbol(name) for name in [*names, *derived["parameters"], "t"]}
    symbols |= {f"{name}_dot": sp.Symbol(f"{name}_dot") for name in names}
    A = sp.Matrix([[sp.sympify(entry, locals=symbols) for entry in row]
                   for row in found["jacobian"]])
    rates = document.get("steady") or {}
    qdot0 = sp.Matrix([rates.get(f"{name}_dot", 0.0) for name in names])
    point = {symbols[k]: v for k, v in derived["parameters"].items() if v is not None}
    point |= {symbols[k]: v for k, v in document["equilibrium"].items()}
    point[symbols["t"]] = 0.0
    B = (A * qdot0).jacobian(q)
    return {"A": np.array(A.subs(point).evalf(), dtype=float),
            "B": np.array(B.subs(point).evalf(), dtype=float),
            "holonomic": np.array([kind == "holonomic" for kind in found["kinds"]])}


def check_modes(document: dict, constraints: dict | None = None) -> None:
    """Each mode's s and shape v satisfy (s^2 M + s C + K) v = 0; with constraints on the
    coordinates listed (a nonholonomic model keeps them all), (s^2 M + s C + K) v lies in the
    range of A^T (the multipliers' forces) and the linearized constraint holds."""
    _has(document, "equilibrium", "stable", "coordinates", "mass_matrix", "damping_matrix",
         "stiffness_matrix", "modes")
    names = document["coordinates"]
    M, C, K = (np.array(document[k], dtype=float)
               for k in ("mass_matrix", "damping_matrix", "stiffness_matrix"))
    n = len(names)
    assert M.shape == C.shape == K.shape == (n, n)
    assert document["modes"], "modes exited 0 with no mode"
    for number, mode in enumerate(document["modes"], 1):
        _has(mode, "frequency", "damping_ratio", "growth_rate", "shape", "amplitude", "phase")
        amplitude = np.array([mode["amplitude"][q] for q in names], dtype=float)
        phase = np.array([mode["phase"][q] for q in names], dtype=float)
        v = amplitude * np.exp(1j * phase)
        assert np.linalg.norm(v) > 0, f"mode {number}: a zero shape"
        wn, zeta, growth = mode["frequency"], mode["damping_ratio"], mode["growth_rate"]
        imag = wn * math.sqrt(max(0.0, 1.0 - zeta**2)) if wn else 0.0
        # s = Re s + i Im s, the sign of Im s is the shape's phase convention: either conjugate
        best = math.inf
        for s in (complex(growth, imag), complex(growth, -imag)):
            P = s * s * M + s * C + K
            scale = (abs(s) ** 2 * np.linalg.norm(M) + abs(s) * np.linalg.norm(C)
                     + np.linalg.norm(K)) * np.linalg.norm(v)
            r = P @ v
            if constraints is not None:
                A, B, holonomic = constraints["A"], constraints["B"], constraints["holonomic"]
                r = r - A.T @ np.linalg.lstsq(A.T, r, rcond=None)[0]
                linear = np.where(holonomic[:, None], A, s * A + B) @ v
                size = (abs(s) + 1) * (np.linalg.norm(A) + np.linalg.norm(B)) * np.linalg.norm(v)
                r = np.concatenate([r, linear * scale / size])
            best = min(best, float(np.linalg.norm(r)) / max(scale, 1e-300))
        assert best < 1e-9, (f"mode {number} (s = {growth} ± {imag}i): relative residual "
                              f"{best:.2e} of (s^2 M + s C + K) v = 0")


def check_speeds(document: dict) -> None:
    _has(document, "coordinates", "speed", "M", "C1", "K0", "K2", "speeds", "eigenvalues")
    M, C1, K0, K2 = (np.array(document[k], dtype=float) for k in ("M", "C1", "K0", "K2"))
    n = M.shape[0]
    C0 = np.array(document.get("C0", np.zeros((n, n))), dtype=float)
    K1 = np.array(document.get("K1", np.zeros((n, n))), dtype=float)
    g = float(document.get("g", 1.0))
    assert document["speeds"] and len(document["eigenvalues"]) == len(document["speeds"])
    for v, values in zip(document["speeds"], document["eigenvalues"], strict=True):
        C, K = C0 + v * C1, g * K0 + v * K1 + v * v * K2
        for re_s, im_s in values:
            s = complex(re_s, im_s)
            P = s * s * M + s * C + K
            scale = abs(s) ** 2 * np.linalg.norm(M) + abs(s) * np.linalg.norm(C) + np.linalg.norm(K)
            smallest = np.linalg.svd(P, compute_uv=False)[-1]
            assert smallest <= 1e-9 * max(scale, 1e-300), (
                f"speed {v}: {s} is no eigenvalue (sigma_min {smallest:.2e}, scale {scale:.2e})")


def check_derive(document: dict) -> None:
    _has(document, "name", "coordinates", "parameters", "kinetic_energy", "potential_energy",
         "generalized_forces", "mass_matrix", "forcing", "equations", "accelerations")
    names = document["coordinates"]
    assert names and set(document["equations"]) == set(names)
    assert len(document["mass_matrix"]) == len(names) == len(document["forcing"])


def check_forces(document: dict) -> None:
    _has(document, "configuration", "generalized_forces", "contributions", "units")
    assert document["generalized_forces"]


def check_equilibria(document: dict) -> None:
    _has(document, "equilibria")
    for point in document["equilibria"]:
        _has(point, "coordinates", "stable")


def check_statics(document: dict) -> None:
    _has(document, "configuration", "solved", "units", "reactions", "shares", "residual")
    assert document["solved"], "statics exited 0 with nothing solved"
    assert document["residual"] < 1e-6 * max(1.0, *(abs(v) for v in document["solved"].values()))


def check_simulate(document: dict) -> None:
    _has(document, "model", "status", "t_end", "t_final", "final_state", "samples")
    assert document["status"] == "finished" and document["t_final"] == document["t_end"]
    residual = document.get("max_constraint_residual")
    if residual is not None:
        assert residual < 1e-6, f"the constraints do not hold: residual {residual}"


def check_dynamics(document: dict) -> None:
    _has(document, "coordinates", "q", "v", "mass_matrix", "bias_forces", "gravity")
    M = np.array(document["mass_matrix"], dtype=float)
    assert np.allclose(M, M.T, rtol=1e-12, atol=1e-14 * np.abs(M).max()), "M is not symmetric"


def check_crosscheck(document: dict) -> None:
    _has(document, "agree", "coordinates")
    assert document["agree"]


def check_units(document: dict) -> None:
    _has(document, "consistent", "issues")
    assert document["consistent"] == (not document["issues"])


def check_sweep(document: dict) -> None:
    _has(document, "ok", "missing")
    assert document["ok"] == 3, f"{document['ok']} of 3 points computed: {document['missing']}"


CHECKS = {
    "derive": check_derive, "forces": check_forces, "equilibria": check_equilibria,
    "modes": check_modes, "modes-steady": check_modes, "speeds": check_speeds,
    "statics": check_statics, "simulate": check_simulate, "crosscheck": check_crosscheck,
    "units": check_units, "dynamics": check_dynamics, "sweep": check_sweep,
}


def assert_refused_in_one_line(code: int, out: str, err: str) -> None:
    assert "Traceback" not in err, err[-2000:]
    assert code == 2, f"exit {code}\nstdout: {out[-1000:]}\nstderr: {err[-2000:]}"
    lines = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(lines) == 1, f"expected one 'error:' line, got:\n{err[-2000:]}"
    others = [line for line in err.splitlines() if line and not line.startswith(("error:",
                                                                                  "warning:"))]
    assert not others, f"stderr beyond the error line:\n{err[-2000:]}"


# -- the arguments of each cell ---------------------------------------------------------------

def _answer_file(cli, model: str, folder: Path) -> Path | None:
    """The model's own derivation as an answer file (T, V, D, Q, equations, multipliers),
    written out in the model's names (--expand: no intermediate quantities)."""
    code, out, _ = cli("derive", model, "--json", "--expand")
    if code != 0:
        return None
    d = json.loads(out)
    lines = ["[energy]", f"T = {json.dumps(d['kinetic_energy'])}",
             f"V = {json.dumps(d['potential_energy'])}"]
    if d.get("dissipation") not in (None, "0"):
        lines.append(f"D = {json.dumps(d['dissipation'])}")
    lines.append("[generalized_forces]")
    lines += [f"{q} = {json.dumps(e)}" for q, e in d["generalized_forces"].items()]
    lines.append("[equations]")
    lines += [f"{q} = {json.dumps(e)}" for q, e in d["equations"].items()]
    if d.get("constraints"):
        lines += ["[multipliers]", f"names = {json.dumps(d['constraints']['multipliers'])}"]
    path = folder / "answer.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _sweep_args(name: str) -> list[str]:
    parameter = SWEEP_VARY.get(name)
    table = _table(name)
    if parameter is None:  # no parameter: vary the first coordinate's initial value
        first = next(iter(table["coordinates"]))
        return ["--vary", f"{first}=0.1:0.3:3", "--compute", "simulate", "--t-end", "0.05",
                "--time-samples", "5"]
    value = table.get("parameters", {}).get(parameter, 9.81 if parameter == "g" else 1.0)
    value = value["value"] if isinstance(value, dict) else value
    return ["--vary", f"{parameter}={0.9 * value!r}:{1.1 * value!r}:3"]


def _args(command: str, name: str, model: str, folder: Path, cli, request) -> list[str] | None:
    json_ = ["--json"]
    if command == "derive":
        return ["derive", model, *json_]
    if command in ("forces", "equilibria", "modes", "crosscheck", "units", "dynamics"):
        return [command, model, *json_]
    if command == "modes-steady":
        return ["modes", model, *STEADY[name], *json_]
    if command == "speeds":
        return ["speeds", model, "--points", "5", *json_]
    if command == "statics":
        return ["statics", model, *STATICS[name], *json_]
    if command == "simulate":
        return ["simulate", model, "--t-end", "0.05", "--samples", "11", *json_]
    if command == "check":
        answer = _answer_file(cli, model, folder)
        return None if answer is None else ["check", model, str(answer), *json_]
    if command == "codegen":
        return ["codegen", model, "--lang", "c", "--out", str(folder / "c")]
    if command == "sweep":
        return ["sweep", model, *_sweep_args(name), "--json", "--scheduler",
                request.getfixturevalue("scheduler")]
    raise AssertionError(command)


# -- the matrix -------------------------------------------------------------------------------

@pytest.mark.parametrize(("command", "name"), list(_cells()))
def test_cell(cli, tmp_path, request, command, name):
    model = MODELS[name]
    args = _args(command, name, model, tmp_path, cli, request)
    if args is None:  # check: the model cannot be derived (its derive cell says why)
        pytest.skip("derive refuses this model: no answer to check")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")  # as the command line shows them
        code, out, err = cli(*args)
    leaked = [f"{w.category.__name__}: {w.message}" for w in caught
              if not issubclass(w.category, DeprecationWarning | PendingDeprecationWarning)]
    assert not leaked, f"Python warnings leak to stderr: {leaked[:5]}"
    if code == 1 and command in ("check", "units"):  # a verdict: judged below
        assert "Traceback" not in err, err[-2000:]
    elif code != 0:
        assert_refused_in_one_line(code, out, err)
        return
    assert "Traceback" not in err, err[-2000:]
    stray = [line for line in err.splitlines() if line and not line.startswith("warning: ")]
    assert not stray, f"stderr beyond 'warning:' lines: {stray[:5]}"
    if command == "codegen":
        _check_codegen(tmp_path / "c")
        return
    assert out.strip(), f"{command} exited 0 and printed nothing"
    document = json.loads(out)
    assert _finite(document), "JSON with a non-finite number"
    if command == "check":
        _check_own_answer(cli, model, code, document)
        return
    if command in ("modes", "modes-steady"):
        check_modes(document, mode_constraints(cli, model, document))
        return
    CHECKS[command](document)


def _check_own_answer(cli, model: str, code: int, document: dict) -> None:
    """The model's own derivation is correct: every finding correct or equivalent, but for
    units mismatches in a model that is itself dimensionally inconsistent (numbers without
    units, as in T = 3*x_dot^2/2), which `units` must then report too."""
    _has(document, "verdict", "findings")
    wrong = [f for f in document["findings"] if f["status"] == "wrong"]
    if code == 0:
        assert document["verdict"] == "correct" and not wrong, document
        return
    assert all(f["code"] == "units_mismatch" for f in wrong), wrong
    units_code, out, _ = cli("units", model, "--json")
    assert units_code == 1 and not json.loads(out)["consistent"]


def _check_codegen(folder: Path) -> None:
    sources = sorted(folder.glob("*.c"))
    headers = sorted(folder.glob("*.h"))
    assert len(sources) == 1 and len(headers) == 1, sorted(p.name for p in folder.iterdir())
    assert sources[0].stat().st_size > 0
    compiler = shutil.which("cc") or shutil.which("gcc")
    if compiler:  # the C compiles on its own (C99, libm only)
        result = subprocess.run([compiler, "-std=c99", "-fsyntax-only", "-Wall", str(sources[0])],
                                capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stderr[-2000:]


def test_matrix_covers_every_example_and_kind():
    """Every built-in example (as `lagrangian examples --json` lists them) has its row."""
    from lagrangian.cli import main  # noqa: F401  (the same list the command prints)
    from lagrangian.model.examples import example_summary

    listed = {example_summary(name)["name"] for name in example_names()}
    assert listed <= set(MODELS)
    assert set(SWEEP_VARY) == set(MODELS)
    assert {"whipple_bicycle", "coin_steady"} <= set(STEADY)
