"""Simulation results as tables: CSV or Parquet files, written atomically."""

from __future__ import annotations

import io
from pathlib import Path

from ..errors import InputError, require_extra
from ..simulation.result import SimulationResult
from .files import atomic_write

TABLE_FORMATS = {".csv": "CSV", ".parquet": "Parquet"}
# the Parquet engine pandas uses: the optional extra [parquet] (docs/dependencies.md)
PARQUET_MODULES = ("pyarrow",)


def result_frame(result: SimulationResult):
    """A pandas DataFrame, one row per sample: t, <q>, <q>_dot, energy, lambda_*, residual_*,
    power (SI units)."""
    import pandas as pd

    return pd.DataFrame(result.columns())


def csv_text(result: SimulationResult) -> str:
    """The CSV text of the result (full double precision, a header row of column names)."""
    columns = result.columns()
    names = list(columns)
    lines = [",".join(names)]
    rows = zip(*(columns[name] for name in names), strict=True)
    lines.extend(",".join(repr(float(value)) for value in row) for row in rows)
    return "\n".join(lines) + "\n"


def check_table_path(path: str | Path) -> Path:
    """The path of a table, refused unless it names a format we write (.csv, .parquet)."""
    path = Path(path)
    if path.suffix.lower() not in TABLE_FORMATS:
        raise InputError(f"cannot write {path}: use a .csv or .parquet file name", field="table")
    if path.suffix.lower() == ".parquet":  # asked before the run, not after it
        require_extra("parquet", PARQUET_MODULES, "writing Parquet (.parquet)")
    return path


def write_table(result: SimulationResult, path: str | Path, *, protect: tuple[Path, ...] = ()
                ) -> Path:
    """Write CSV (``.csv``) or Parquet (``.parquet``) atomically; never over a protected file."""
    path = check_table_path(path)
    if path.suffix.lower() == ".csv":
        return atomic_write(path, csv_text(result), protect=protect)
    buffer = io.BytesIO()
    result_frame(result).to_parquet(buffer, index=False)
    return atomic_write(path, buffer.getvalue(), protect=protect)
