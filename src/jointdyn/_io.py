"""The one home of writing outputs: atomic files (nothing half-written is ever left behind), a
Dataset as netCDF + CSV, values for JSON.

xarray and pandas are not imported here: the Dataset's own methods write it.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["atomic_path", "atomic_write_text", "jsonable", "point_table", "write_dataset"]


@contextlib.contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path beside ``path``; move it into place on success.

    On an exception the temporary file is removed and ``path`` is untouched.
    The suffix of the temporary file matches ``path`` (writers such as
    Matplotlib pick the format from it).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        # mkstemp makes the file private (0600); give it the usual mode
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def atomic_write_text(path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text)
    return Path(path)


def write_table_and_figure(out, stem: str, table, png: bytes) -> list:
    """``stem.csv`` (a DataFrame, floats to 17 digits so that they read back exactly) and ``stem.png``
    (its bytes) in the folder ``out``, each written atomically; returns the two paths."""
    out = Path(out)
    csv_text = table.to_csv(index=False, float_format="%.17g")
    paths = [atomic_write_text(out / f"{stem}.csv", csv_text), out / f"{stem}.png"]
    with atomic_path(paths[1]) as tmp:
        Path(tmp).write_bytes(png)
    return paths


def jsonable(values):
    """``values`` as JSON takes them: arrays, lists and tuples as (nested) lists of Python numbers (through
    NumPy), NaN and infinities as None (JSON has no NaN); any other value as it is, a non-finite float as
    None."""
    if isinstance(values, (np.ndarray, list, tuple)):
        return _clean(np.asarray(values).tolist())
    return None if isinstance(values, float) and not math.isfinite(values) else values


def _clean(v):
    if isinstance(v, list):
        return [_clean(x) for x in v]
    return None if isinstance(v, float) and not math.isfinite(v) else v


def point_table(ds):
    """The variables of ``ds`` on its dimension ``point`` alone, one row per point (a pandas DataFrame with
    the ``point`` column first)."""
    flat = ds.drop_dims([d for d in ds.dims if d != "point"])
    return flat.to_dataframe().reset_index()


def write_dataset(ds, out, stem: str, table=point_table) -> list:
    """Write ``ds`` as ``out/<stem>.nc`` (netCDF3, scipy engine) and ``out/<stem>.csv`` (``table(ds)``,
    default :func:`point_table`), each atomically; returns both paths.

    The netCDF file leaves out the dimensions of length 0 and the variables on them (e.g. the per-contact
    variables of a system whose only contacts are interfaces): they hold no values, and a netCDF3 file
    with such a variable cannot be read back (scipy's reader fails on it)."""
    out = Path(out)
    nc, csv = out / f"{stem}.nc", out / f"{stem}.csv"
    empty = [d for d, size in ds.sizes.items() if size == 0]
    with atomic_path(nc) as tmp:
        (ds.drop_dims(empty) if empty else ds).to_netcdf(tmp, engine="scipy")
    with atomic_path(csv) as tmp:
        table(ds).to_csv(tmp, index=False)
    return [nc, csv]
