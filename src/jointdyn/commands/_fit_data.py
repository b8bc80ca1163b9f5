"""The measured data of ``jointdyn fit``: read by jointdyn's one CSV reader and checked before fitting.

Every refusal names the option (``--input``, ``--backbone``), the file, the
column and the line, so that a user finds the bad value in the file; the
library's fits (:func:`jointdyn.fit_loops`, :func:`jointdyn.fit_backbone`)
would name only their arguments. Sizes and magnitudes are bounded before
any fitting (``config.FIT_MAX_LOOP_SAMPLES``,
``config.FIT_MAX_BACKBONE_POINTS``, ``FIT_MAX_MAGNITUDE``).
"""

from __future__ import annotations

import numpy as np

from .. import config
from ..files.tables import RowBound, Spec, data_line, read_table

__all__ = ["LOOPS", "BACKBONE", "read_columns", "read_loops", "read_backbone", "plausibility"]

#: largest magnitude of a measured value a fit computes with: its squares, products and sums over
#: every sample must stay finite in double precision (1e100 squared is 1e200)
FIT_MAX_MAGNITUDE = 1e100

#: a fretting rig's record: time, tangential displacement, normal load, tangential force
LOOPS = Spec(
    columns=("t", "x", "N", "T"),
    units={"t": "s", "x": "m", "N": "N", "T": "N"},
    aliases={"t": ("time",), "x": ("x", "displacement"),
             "N": ("n", "normal load", "normal force", "normal_load", "normal_force"),
             "T": ("tangential force", "friction force", "tangential_force", "friction_force")},
    expected="expected a header row naming the columns t, x, N, T in SI units (s, m, N, N), "
             "e.g. 't,x,N,T' or 't [s];x [m];N [N];T [N]', then one row of numbers per sample",
    increasing="t",
    min_rows=10,  # as jointdyn.fit_loops
)
#: one mode's measured backbone: amplitude, natural frequency and damping ratio per point
BACKBONE = Spec(
    columns=("amplitude_m", "omega_rad_s", "damping_ratio"),
    units={"amplitude_m": "m", "omega_rad_s": "rad/s", "damping_ratio": ""},
    aliases={"amplitude_m": ("amplitude",), "omega_rad_s": ("omega",), "damping_ratio": ("damping", "zeta")},
    expected="expected a header row naming the columns amplitude_m, omega_rad_s, damping_ratio "
             "(m, rad/s, no unit), then one row of numbers per point",
    min_rows=4,
)
_LOOP_ROWS = RowBound(config.FIT_MAX_LOOP_SAMPLES, "config.FIT_MAX_LOOP_SAMPLES: the least squares evaluates the "
                                                   "law over every sample some hundred times; 1e6 samples take "
                                                   "seconds")
_BACKBONE_ROWS = RowBound(config.FIT_MAX_BACKBONE_POINTS, "config.FIT_MAX_BACKBONE_POINTS: every point costs a "
                                                          "describing function per evaluation, about 4 ms of the "
                                                          "whole fit")
#: largest slip displacement fy / kt (m) of a plausible joint: loops of micrometres to a millimetre
_PLAUSIBLE_SLIP_M = 1e-2


def _where(name, path) -> str:
    return f"{name} {str(path)!r}"


def _magnitudes(name, path, lay, cols: dict, *, top: float = FIT_MAX_MAGNITUDE) -> None:
    """Every value within ``top`` in magnitude, else the column and the line of the first beyond."""
    for key, v in cols.items():
        bad = np.flatnonzero(~(np.abs(v) <= top))
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"{_where(name, path)} line {data_line(path, lay, name, i)}: {key} = {float(v[i])!r} "
                             f"is beyond the range a fit computes with (|{key}| <= {top:g}, "
                             "FIT_MAX_MAGNITUDE: its squares and products must stay finite)")


def _row_check(name, path, lay, key, v, ok, what: str) -> None:
    """ValueError naming the first row where ``ok`` is False."""
    bad = np.flatnonzero(~ok)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"{_where(name, path)} line {data_line(path, lay, name, i)}: column {key} must be {what}, "
                         f"got {key} = {float(v[i])!r}")


def read_columns(path, columns, name: str) -> dict:
    """The named columns of a CSV file with a header row, as float arrays (jointdyn's one CSV reader).

    Units in the header are not checked; at least 4 data rows.

    Raises
    ------
    ValueError
        One line naming ``name``, the file and the line.
    """
    spec = Spec(columns=tuple(columns), units={}, aliases={},
                expected=f"expected a header row naming the columns {', '.join(columns)}, then one row of numbers "
                         "per row of data", min_rows=4)
    cols, _ = read_table(path, spec, name=name)
    return dict(zip(columns, cols))


def read_loops(path, name: str = "--input") -> dict:
    """Measured loops ``t, x, N, T`` (s, m, N, N), checked: at most ``config.FIT_MAX_LOOP_SAMPLES``
    rows, values within ``FIT_MAX_MAGNITUDE``, x moving, some N > 0, some T != 0.

    Raises
    ------
    ValueError
        One line naming ``name``, the file, the column (and the line).
    """
    cols, lay = read_table(path, LOOPS, name=name, bound=_LOOP_ROWS)
    d = dict(zip(LOOPS.columns, cols))
    _magnitudes(name, path, lay, {k: d[k] for k in ("x", "N", "T")})
    first, last = lay.data_line, data_line(path, lay, name, d["t"].size - 1)
    rows = f"lines {first} to {last}"
    if d["x"].min() == d["x"].max():
        raise ValueError(f"{_where(name, path)} column x holds {float(d['x'][0])!r} on every row ({rows}): "
                         "x must move for a loop to be fitted")
    if not np.any(d["N"] > 0.0):
        raise ValueError(f"{_where(name, path)} column N is <= 0 on every row ({rows}; largest "
                         f"{float(d['N'].max())!r} N): the contact must be loaded (N > 0) at some samples")
    if not np.any(d["T"] != 0.0):
        raise ValueError(f"{_where(name, path)} column T is 0 on every row ({rows}): the contact must carry a "
                         "tangential force at some samples")
    return d


def read_backbone(path, name: str = "--backbone", mass: float | None = None) -> dict:
    """A measured backbone ``amplitude_m, omega_rad_s, damping_ratio``, checked: at most
    ``config.FIT_MAX_BACKBONE_POINTS`` rows, amplitude and omega > 0, damping >= 0, every value
    within ``FIT_MAX_MAGNITUDE`` and the modal force ``--mass`` omega^2 amplitude too.

    Raises
    ------
    ValueError
        One line naming ``name``, the file, the column and the line.
    """
    cols, lay = read_table(path, BACKBONE, name=name, bound=_BACKBONE_ROWS)
    d = dict(zip(BACKBONE.columns, cols))
    top, low = FIT_MAX_MAGNITUDE, 1.0 / FIT_MAX_MAGNITUDE
    for key in ("amplitude_m", "omega_rad_s"):
        _row_check(name, path, lay, key, d[key], d[key] > 0.0, "> 0 (allowed range (0, inf))")
    _row_check(name, path, lay, "damping_ratio", d["damping_ratio"], d["damping_ratio"] >= 0.0,
               ">= 0 (allowed range [0, inf))")
    for key in ("amplitude_m", "omega_rad_s"):
        _row_check(name, path, lay, key, d[key], (d[key] >= low) & (d[key] <= top),
                   f"in [{low:g}, {top:g}] (FIT_MAX_MAGNITUDE: the fit's products must stay finite)")
    _magnitudes(name, path, lay, {"damping_ratio": d["damping_ratio"]})
    if mass is not None:
        force = mass * d["omega_rad_s"] ** 2 * d["amplitude_m"]
        _row_check(name, path, lay, "amplitude_m", d["amplitude_m"], force <= top,
                   f"such that --mass x omega_rad_s^2 x amplitude_m (modal force, N) is at most {top:g} "
                   f"(FIT_MAX_MAGNITUDE; --mass {mass:g} kg)")
    return d


def plausibility(fit, measured: dict | None = None) -> list:
    """Warnings (one line each) when the data or the fitted values are implausible for SI units:
    a joint whose slip displacement fy / kt, or whose loops' x range, exceeds 1 cm was most likely
    given in mm (or um) as if in metres."""
    out = []
    if measured is not None and "x" in measured:
        span = float(np.ptp(measured["x"]))
        if span > _PLAUSIBLE_SLIP_M:
            out.append(f"x spans {span:.4g} m peak to peak: a joint's loops span micrometres to millimetres; "
                       "the columns are in SI units (x in m): if x is in mm, divide it by 1000")
    kt, fy = fit.parameters.get("kt"), fit.parameters.get("fy_N")
    if kt and fy and fy / kt > _PLAUSIBLE_SLIP_M:
        out.append(f"the fitted slip displacement fy_N / kt = {fy / kt:.4g} m is implausible for a joint "
                   "(micrometres to a millimetre): check that the file's lengths are in metres")
    return out
