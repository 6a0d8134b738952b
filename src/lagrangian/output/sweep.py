"""A study's results as an xarray Dataset, its files (NetCDF or Zarr), plot and JSON summary.

One dimension per varied name (and ``member`` for an ensemble); ``status`` says 'ok' or why a
point is missing (its numbers are NaN). xarray is imported here, on the sweep path only.
"""

from __future__ import annotations

import io
import json
import os
import shutil
import tempfile
import uuid
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..analysis.study import NOT_COMPUTED, OK, Study, layout
from ..errors import InputError, require_extra
from .files import atomic_write
from .plots import notebook_figure, plain_text

STUDY_FORMATS = (".nc", ".zarr")
PLOT_DPI = 120

DESCRIPTIONS = {
    "frequency": ("rad/s", "natural frequency of each mode, ascending"),
    "damping_ratio": ("1", "damping ratio of each mode"),
    "growth_rate": ("1/s", "largest real part of the mode's eigenvalues (> 0: it grows)"),
    "stable": ("1", "1 when no mode grows (linear stability), 0 when one does"),
    "equilibrium": ("SI", "the equilibrium the modes are about (System.modes' choice)"),
    "configuration": ("SI", "each equilibrium found, in the coordinates' units"),
    "shape": ("1", "mode shape, first component of largest magnitude +1"),
    "count": ("1", "number of equilibria found"),
    "final": ("SI", "state at the last sample"),
    "minimum": ("SI", "smallest value of each state component over the samples"),
    "maximum": ("SI", "largest value of each state component over the samples"),
    "t_final": ("s", "time of the last sample"),
    "invariant_drift": ("1", "largest change of the monitored invariant (T + V, the Jacobi "
                        "integral or the work balance) relative to its size"),
    "stop_time": ("s", "time the stop condition fired (NaN: it did not)"),
    "trajectory": ("SI", "state on the common time grid"),
    "eigenvalue_real": ("1/s", "real part of each eigenvalue of the reduced equations about the "
                        "steady motion, largest first (> 0: it grows)"),
    "eigenvalue_imag": ("rad/s", "imaginary part of each eigenvalue, in the order of "
                        "eigenvalue_real"),
    "status": ("", "'ok', or why the point has no numbers"),
}


# The attribute that marks a file or store as a study this project wrote: the only thing an
# output path may already hold, since a command never replaces what it did not create.
WRITTEN_BY = "lagrangian sweep"
_LEGACY_ATTRS = {"model", "compute", "points", "finished", "failed", "about"}


# The packages of a study, the optional extra [sweep] (docs/dependencies.md): the engine, the
# Dataset, and the writer of each file format.
STUDY_MODULES = ("dask", "distributed", "xarray")  # dask.distributed imports even without it
STUDY_WRITERS = {".nc": ("h5netcdf", "h5py"), ".zarr": ("zarr",)}


def require_study_packages(out: str | Path | None = None) -> None:
    """The study stack (and the writer of ``out``'s format) importable, or a MissingExtraError
    naming the extra [sweep]: asked before any work, not when the results are written."""
    require_extra("sweep", STUDY_MODULES, "a parameter study (sweep)")
    suffix = Path(out).suffix.lower() if out is not None else ""
    if suffix in STUDY_WRITERS:
        require_extra("sweep", STUDY_WRITERS[suffix], f"writing a study as {suffix}")


def check_study_path(path: str | Path) -> Path:
    """The output of a study: *.nc (NetCDF through h5netcdf) or *.zarr (a Zarr store), checked
    before any work: where something is already there it must be a study this project wrote."""
    path = Path(path)
    if path.suffix.lower() not in STUDY_FORMATS:
        raise InputError(f"a study is written as NetCDF (*.nc) or Zarr (*.zarr), not '{path}'",
                         field="out")
    require_study_packages(path)  # is_study below reads the file with its format's reader
    if path.is_symlink():
        raise InputError(f"{path} is a symbolic link: refusing to replace it", field="out")
    if path.exists() and not is_study(path):
        what = "a directory" if path.is_dir() else "a file"
        raise InputError(f"{path} exists and is {what} that is not a study written by lagrangian: "
                         "refusing to replace it (move it away or choose another output path)",
                         field="out")
    return path


def is_study(path: Path) -> bool:
    """Whether ``path`` holds a study written by write_study (its attributes say so); reads
    only the attributes, and never raises on a foreign or damaged file."""
    try:
        if path.is_dir():
            if path.suffix.lower() != ".zarr":
                return False
            attrs_file = path / ".zattrs"
            if attrs_file.is_symlink() or not attrs_file.is_file() \
                    or attrs_file.stat().st_size > 2**20:
                return False
            attrs = json.loads(attrs_file.read_text(encoding="utf-8"))
        else:
            if path.suffix.lower() != ".nc":
                return False
            import h5py

            with h5py.File(path, "r") as handle:
                attrs = {k: handle.attrs[k] for k in handle.attrs}
        if not isinstance(attrs, dict):
            return False
        written_by = attrs.get("written_by")
        if isinstance(written_by, bytes):
            written_by = written_by.decode("utf-8", "replace")
        return written_by == WRITTEN_BY or _LEGACY_ATTRS <= set(attrs)
    except Exception:  # noqa: BLE001 - a file we cannot read is not ours
        return False


def check_study_plot_path(path: str | Path) -> Path:
    path = Path(path)
    if path.suffix.lower() != ".png":
        raise InputError(f"the plot is written as PNG; name the file *.png (got '{path}')",
                         field="plot")
    return path


def study_dataset(study: Study, arrays: Mapping[str, np.ndarray], finished: int | None = None):
    """The Dataset of a study from the flat arrays of every point (rows in flat point order)."""
    import xarray as xr

    model = study.model
    coordinates = [c.name for c in model.coordinates]
    units = {p.name: p.unit for p in model.parameters}
    units.update({c.name: c.unit for c in model.coordinates})
    units.update({c.velocity.name: f"({c.unit})/s" if c.unit else None
                  for c in model.coordinates})
    coords: dict[str, object] = {}
    for name, values in study.axes:
        coords[name] = (name, np.asarray(values, float), {"units": units.get(name) or ""})
    if study.draws:
        coords["member"] = ("member", np.arange(len(study.draws[0][1])))
        for name, values in study.draws:
            coords[name] = ("member", np.asarray(values, float), {"units": units.get(name) or ""})
    data_vars = {}
    extra_sizes = {}
    for name, (extra, _) in layout(study).items():
        array = np.asarray(arrays[name], float)
        for d, size in zip(extra, array.shape[1:], strict=True):
            extra_sizes[d] = size
        unit, text = DESCRIPTIONS[name]
        data_vars[name] = ((*study.dims, *extra), array.reshape(*study.shape, *array.shape[1:]),
                           {"units": unit, "description": text})
    status = np.asarray(arrays["status"]).astype(str)
    data_vars["status"] = (study.dims, status.reshape(study.shape),
                           {"description": DESCRIPTIONS["status"][1]})
    if "mode" in extra_sizes:
        coords["mode"] = ("mode", np.arange(1, extra_sizes["mode"] + 1))
    if "coordinate" in extra_sizes:
        coords["coordinate"] = ("coordinate", np.array(coordinates))
    if "equilibrium" in extra_sizes:
        coords["equilibrium"] = ("equilibrium", np.arange(extra_sizes["equilibrium"]))
    if "eigenvalue" in extra_sizes:
        coords["eigenvalue"] = ("eigenvalue", np.arange(1, extra_sizes["eigenvalue"] + 1))
    if "state" in extra_sizes:
        coords["state"] = ("state", np.array([*coordinates, *(f"{c}_dot" for c in coordinates)]))
    if "time" in extra_sizes:
        options = study.simulation
        coords["time"] = ("time", np.linspace(0.0, options.t_end, options.samples), {"units": "s"})
    attrs = {"written_by": WRITTEN_BY, "model": model.name, "compute": study.compute,
             "points": study.size,
             "about": ", ".join(f"{k}={v:.6g}" for k, v in study.about),
             "finished": study.size if finished is None else int(finished),
             "failed": int(np.sum((status != OK) & (status != NOT_COMPUTED)))}
    if study.warnings:
        attrs["warnings"] = "\n".join(study.warnings)
    if study.simulation is not None:
        options = study.simulation
        attrs.update({"invariant": str(study.eom.invariant_kind), "t_end": options.t_end,
                      "method": options.method, "rtol": options.rtol, "atol": options.atol,
                      "stop_when": options.stop_when or ""})
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def write_study(dataset, path: str | Path, *, protect: tuple[Path, ...] = ()) -> Path:
    """NetCDF (h5netcdf) for *.nc, a Zarr store for *.zarr; written beside under a fresh name
    and moved into place, so a half-written file never replaces a good one. What ``path``
    already holds is replaced only when it is a study this project wrote (check_study_path)."""
    path = Path(path)
    for guarded in protect:
        if path.exists() and guarded.exists() and path.resolve() == guarded.resolve():
            raise FileExistsError(f"{path}: refusing to overwrite an input file")
    path.parent.mkdir(parents=True, exist_ok=True)
    path = check_study_path(path)
    if path.suffix.lower() == ".nc":
        handle, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        os.close(handle)
        temporary = Path(name)
        try:
            dataset.to_netcdf(temporary, engine="h5netcdf")
            os.replace(temporary, path)  # a file over a file: atomic
        finally:
            temporary.unlink(missing_ok=True)
        return path
    temporary = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp"))
    try:
        # Zarr format 2: fixed-width text (status) and consolidated metadata are in its spec.
        dataset.to_zarr(temporary, mode="w", consolidated=True, zarr_format=2)
        old = None
        if path.exists():  # our own earlier study (checked above): set aside, then removed
            old = path.with_name(f".{path.name}.old-{uuid.uuid4().hex[:8]}")
            os.replace(path, old)
        os.replace(temporary, path)
        if old is not None:
            shutil.rmtree(old)
    finally:
        if temporary.exists():
            shutil.rmtree(temporary)
    return path


def read_study(path: str | Path):
    """A study written by ``write_study``, loaded into memory."""
    require_study_packages(path)
    import xarray as xr

    path = Path(path)
    if path.suffix.lower() == ".zarr":
        return xr.open_zarr(path).load()
    with xr.open_dataset(path, engine="h5netcdf") as dataset:
        return dataset.load()


def study_summary(dataset) -> dict:
    """JSON-ready: what was computed over which grid, how many points failed and why, and the
    range of the main result."""
    status = np.asarray(dataset["status"].values).astype(str).ravel()
    reasons: dict[str, int] = {}
    for s in status:
        if s != OK:
            reasons[s] = reasons.get(s, 0) + 1
    dims = {d: int(dataset.sizes[d]) for d in dataset["status"].dims}
    summary = {"model": dataset.attrs.get("model"), "compute": dataset.attrs.get("compute"),
               "dimensions": dims, "points": int(status.size),
               "ok": int(np.sum(status == OK)), "missing": reasons}
    if dataset.attrs.get("warnings"):
        summary["warnings"] = str(dataset.attrs["warnings"]).split("\n")
    main = {"modes": "frequency", "equilibria": "count", "simulate": "invariant_drift",
            "speeds": "eigenvalue_real"}
    name = main.get(str(dataset.attrs.get("compute")))
    if name in dataset:
        values = np.asarray(dataset[name].values, float)
        finite = values[np.isfinite(values)]
        summary[name] = ({"min": float(finite.min()), "max": float(finite.max())}
                         if finite.size else None)
    if "stable" in dataset and dataset.attrs.get("compute") in ("modes", "speeds"):
        stable = np.asarray(dataset["stable"].values, float)
        summary["stable_points"] = int(np.sum(stable == 1))
        summary["unstable_points"] = int(np.sum(stable == 0))
    return summary


def study_text(dataset, path: Path | None = None) -> str:
    s = study_summary(dataset)
    dims = " x ".join(f"{d} {n}" for d, n in s["dimensions"].items())
    lines = [f"{s['compute']} of {s['model']!r} over {dims}: {s['ok']} of {s['points']} "
             f"points computed"]
    for reason, count in s["missing"].items():
        lines.append(f"  {count} missing: {reason}")
    for key in ("frequency", "count", "invariant_drift", "eigenvalue_real"):
        if s.get(key):
            lines.append(f"  {key}: {s[key]['min']:.6g} .. {s[key]['max']:.6g}")
    if "stable_points" in s:
        lines.append(f"  stable at {s['stable_points']} points, unstable at "
                     f"{s['unstable_points']}")
    if path is not None:
        lines.append(f"Written to {path}")
    return "\n".join(lines) + "\n"


def _speeds_figure(figure, dataset, x):
    """Real parts (growth) and imaginary parts (frequency) of the eigenvalues against the first
    varied name, as the benchmark bicycle's eigenvalues against speed are drawn."""
    axes = figure.subplots(2, 1, sharex=True)
    figure.set_size_inches(8, 6.4)
    rest = {d: 0 for d in dataset["status"].dims[1:]}
    xs = dataset[x].values
    for ax, name, label in ((axes[0], "eigenvalue_real", "real part (1/s)"),
                            (axes[1], "eigenvalue_imag", "imaginary part (rad/s)")):
        variable = dataset[name].isel(rest)
        for k in variable["eigenvalue"].values:
            ax.plot(xs, np.asarray(variable.sel(eigenvalue=k).values, float), ".", ms=3,
                    color=f"C{(k - 1) % 10}")
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_ylabel(label)
        flat_axis(ax, np.asarray(variable.values, float))
    axes[1].set_xlabel(_label(dataset, x))
    axes[0].set_title(plain_text(f"eigenvalues of {dataset.attrs.get('model', '')!s} "
                                 f"against {x}"))
    return figure


def study_figure(dataset):
    """The quantities that vary (drawn_quantities: the frequency, and the damping ratio and
    growth rate where they change) against the (first) varied parameter, a line per mode and
    per value of a second, the model and the varied names in the title; a flat quantity drawn
    flat (flat_axis); for two or more varied parameters also a stability map. For
    equilibria: each equilibrium's coordinates, stable solid, unstable hollow; for an ensemble
    the spread of the final states."""
    compute = dataset.attrs.get("compute")
    dims = [d for d in dataset["status"].dims]
    figure = notebook_figure(figsize=(8, 5), layout="constrained")
    if compute == "simulate":
        return _ensemble_figure(figure, dataset, dims)
    x = dims[0]
    if compute == "speeds":
        return _speeds_figure(figure, dataset, x)
    others = dims[1:]
    if compute == "equilibria":
        ax = figure.subplots()
        eq = dataset["configuration"]
        stable = dataset["stable"]
        reduce = {d: 0 for d in others}
        eq, stable = eq.isel(reduce), stable.isel(reduce)
        xs = dataset[x].values
        for c in eq["coordinate"].values:
            for k in eq["equilibrium"].values:
                y = np.asarray(eq.sel(coordinate=c, equilibrium=k).values, float)
                s = np.asarray(stable.sel(equilibrium=k).values, float)
                ax.plot(xs[s == 1], y[s == 1], "o", color="C0", ms=4)
                ax.plot(xs[s == 0], y[s == 0], "o", mfc="none", color="C3", ms=4)
            ax.set_ylabel(f"equilibrium {c}")
        flat_axis(ax, np.asarray(eq.values, float))
        ax.set_xlabel(_label(dataset, x))
        ax.set_title("stable filled, unstable hollow", fontsize="small")
        figure.suptitle(plain_text(f"Equilibria of {dataset.attrs.get('model', '')} against "
                                   f"{' and '.join(dims)}"))
        return figure
    quantities = drawn_quantities(dataset)
    panels = len(quantities) + int(bool(others))
    figure.set_size_inches(8, 2.6 * panels + 0.7)
    axes = figure.subplots(panels, 1, squeeze=False, sharex=not others)[:, 0]
    series = [{}] if not others else [{others[0]: i} for i in range(dataset.sizes[others[0]])]
    rest = {d: 0 for d in others[1:]}
    for ax, name in zip(axes, quantities, strict=False):
        variable = dataset[name]
        for j, selection in enumerate(series):
            sub = variable.isel({**selection, **rest})
            for k in sub["mode"].values:
                text = f"mode {k}" + (f", {others[0]}={dataset[others[0]].values[j]:.4g}"
                                      if selection else "")
                ax.plot(dataset[x].values, np.asarray(sub.sel(mode=k).values, float),
                        color=f"C{j % 10}", ls=["-", "--", ":", "-."][(k - 1) % 4],
                        marker="." if dataset.sizes[x] <= 30 else None,
                        label=text if len(series) * len(sub["mode"]) <= 12 else None)
        if others or name == quantities[-1]:  # shared x: labelled once, under the last
            ax.set_xlabel(_label(dataset, x))
        ax.set_ylabel(QUANTITY_LABELS[name])
        if name == "growth_rate":
            ax.axhline(0.0, color="0.5", lw=0.8)
        flat_axis(ax, np.asarray(variable.isel(rest).values, float))
        if not others:
            unstable = np.asarray(dataset["stable"].values, float) == 0
            if unstable.any():
                ax.fill_between(dataset[x].values, 0, 1, where=unstable, alpha=0.12,
                                color="C3", transform=ax.get_xaxis_transform(),
                                label="unstable" if ax is axes[0] else None)
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize="small")
    if others:
        ax2 = axes[-1]
        stable = dataset["stable"].isel(rest)
        y = others[0]
        grid = np.asarray(stable.transpose(y, x).values, float)
        ax2.pcolormesh(dataset[x].values, dataset[y].values, grid, cmap="RdYlGn", vmin=0, vmax=1,
                       shading="nearest")
        ax2.set_xlabel(_label(dataset, x))
        ax2.set_ylabel(_label(dataset, y))
        ax2.set_title("stable (green) / unstable (red)", fontsize="small")
    about = dataset.attrs.get("about")
    axes[0].set_title(f"about {about}" if about else
                      "about the equilibrium nearest the initial values", fontsize="small")
    varied = " and ".join(dims)
    figure.suptitle(plain_text(f"Modes of {dataset.attrs.get('model', '')} against {varied}"))
    return figure


# The quantities a modes study draws, each in a panel of its own, with their axis labels.
QUANTITY_LABELS = {"frequency": "natural frequency (rad/s)", "damping_ratio": "damping ratio ζ",
                   "growth_rate": "growth rate (1/s)"}
# A quantity whose values differ by less than this (relative to their size) does not vary.
FLAT_TOLERANCE = 1e-9


def varies(values: np.ndarray) -> bool:
    """Whether the finite values differ by more than round-off (FLAT_TOLERANCE relative)."""
    finite = np.asarray(values, float)
    finite = finite[np.isfinite(finite)]
    if finite.size < 2:
        return False
    return float(np.ptp(finite)) > FLAT_TOLERANCE * max(float(np.max(np.abs(finite))), 1e-300)


def drawn_quantities(dataset) -> list[str]:
    """The quantities of a modes study drawn: the frequency always; the damping ratio and the
    growth rate where they vary over the study (or a mode grows), so a damping sweep shows
    zeta and the decay rate beside a frequency that does not change."""
    names = ["frequency"]
    zeta = np.asarray(dataset["damping_ratio"].values, float)
    if varies(zeta) or bool(np.any(np.abs(zeta[np.isfinite(zeta)]) > 0)):
        names.append("damping_ratio")
    growth = np.asarray(dataset["growth_rate"].values, float)
    if varies(growth) or bool(np.any(growth[np.isfinite(growth)] > 0)):
        names.append("growth_rate")
    return names


def flat_axis(ax, values: np.ndarray) -> None:
    """Values on the y axis as written, never as an offset plus round-off ('1e-12 + 4.4294'):
    a quantity that does not vary is drawn flat, in a range of +-5 % about its value (+-1 about
    zero)."""
    ax.ticklabel_format(axis="y", useOffset=False, style="plain")
    finite = np.asarray(values, float)
    finite = finite[np.isfinite(finite)]
    if finite.size and not varies(finite):
        middle = float(np.median(finite))
        half = 0.05 * abs(middle) if middle != 0 else 1.0
        ax.set_ylim(middle - half, middle + half)


def _ensemble_figure(figure, dataset, dims):
    """One panel per coordinate: with trajectories the median and the 5-95 % band of the members
    against time, else a histogram of the final values; a colour per value of the grid."""
    final = dataset["final"]
    coordinates = list(final["state"].values[: len(final["state"]) // 2])
    grid_dims = [d for d in dims if d != "member"]
    combos = [{}]
    for d in grid_dims:
        combos = [{**c, d: i} for c in combos for i in range(dataset.sizes[d])]
    combos = combos[:6]
    figure.set_size_inches(8, 2.8 * len(coordinates) + 0.4)
    axes = figure.subplots(len(coordinates), 1, squeeze=False)[:, 0]
    for ax, name in zip(axes, coordinates, strict=True):
        for j, combo in enumerate(combos):
            label = ", ".join(f"{d}={dataset[d].values[i]:.4g}" for d, i in combo.items()) or None
            if "trajectory" in dataset:
                values = np.asarray(dataset["trajectory"].isel(combo).sel(state=name)
                                    .transpose(..., "time").values, float)
                values = values.reshape(-1, values.shape[-1])
                t = dataset["time"].values
                with np.errstate(all="ignore"):
                    low, mid, high = np.nanpercentile(values, [5, 50, 95], axis=0)
                ax.fill_between(t, low, high, color=f"C{j}", alpha=0.25)
                ax.plot(t, mid, color=f"C{j}", label=label)
                ax.set_xlabel("t (s)")
            else:
                values = np.asarray(final.isel(combo).sel(state=name).values, float).ravel()
                ax.hist(values[np.isfinite(values)], bins=60, alpha=0.6, color=f"C{j}",
                        label=label)
                ax.set_xlabel(f"final {name}")
        ax.set_ylabel(name if "trajectory" in dataset else "members")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
    members = dataset.sizes.get("member", 1)
    axes[0].set_title(f"{members} members: median and 5-95 % band" if "trajectory" in dataset
                      else f"final state of {members} members", fontsize="small")
    figure.suptitle(plain_text(f"Simulations of {dataset.attrs.get('model', '')} over "
                               f"{' and '.join(dims)}"))
    return figure


def _label(dataset, name: str) -> str:
    unit = dataset[name].attrs.get("units")
    return plain_text(f"{name} ({unit})" if unit else name)


def write_study_plot(dataset, path: str | Path, *, protect: tuple[Path, ...] = ()) -> Path:
    """Draw the study (study_figure) to a PNG file, atomically, never over an input file."""
    path = check_study_plot_path(path)
    buffer = io.BytesIO()
    study_figure(dataset).savefig(buffer, format="png", dpi=PLOT_DPI)
    return atomic_write(path, buffer.getvalue(), protect=protect)
