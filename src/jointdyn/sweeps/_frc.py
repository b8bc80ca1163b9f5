"""Frequency-response sweeps of the paper's friction damper (MODEL.md section 6).

The damper ``m x'' + c x' + k x = F1 sin(w t) - T(x, N(t))`` with
``N = N0 (1 + eta sin(w t + delta))`` is swept in excitation frequency
``gamma = w / w0`` (``w0 = sqrt(k/m)``) on a grid of the paper's groups
``eta = N1/N0``, ``beta = mu N0 / F1`` (or the forcing amplitude ``F1`` in N)
and ``delta``. Every steady state comes from the time-domain solver
:func:`jointdyn.dynamics.steady_state`.

Sweep lines
-----------
Points along gamma are chained: in an ``up`` sweep every point starts from the
steady state of the previous (lower) gamma, in a ``down`` sweep from the next
higher one, so that jumps and coexisting states of the nonlinear response show
as a difference between the two directions. After an ``unbounded`` point the
next one restarts from the solver's linear estimate (``start=None``). One line
(fixed eta, beta or F1, delta, direction) is therefore the unit of parallel
work; lines run on a local process/thread pool or on a Dask cluster and the
result does not depend on where or in which order they ran.

Resume
------
With ``out=DIR`` each finished line is written atomically to
``DIR/lines/<key>.nc`` together with the full description of the line; a
rerun loads every line whose description matches instead of recomputing it.
The assembled Dataset goes to ``DIR/frc.nc`` and a tidy CSV ``DIR/frc.csv``.
The description covers the parameters, not the solver's code: delete
``DIR/lines`` after changing the solver to recompute everything.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import config
from .._io import atomic_path

__all__ = [
    "frc_sweep",
    "LineSpec",
    "STATUS_CODES",
    "VARIABLES",
    "INT_VARIABLES",
    "status_name",
    "to_frame",
    "write_outputs",
    "default_workers",
]

#: status name -> int8 code stored in the Dataset (``status`` variable)
STATUS_CODES = {name: i for i, name in enumerate(config.SWEEP_STATUS)}
_MISSING = config.SWEEP_STATUS_MISSING
_LEGEND = ", ".join(f"{i}: {n}" for i, n in enumerate(config.SWEEP_STATUS)) + f", {_MISSING}: not computed"

#: float result variables of a point, with units and meaning
VARIABLES = {
    "amplitude_q": ("1", "half peak-to-peak of q = kt x / fy over one steady period"),
    "amplitude_m": ("m", "half peak-to-peak of x over one steady period"),
    "offset_m": ("m", "mean of x over one steady period (history dependent while sticking)"),
    "max_abs_m": ("m", "max |x| over one steady period"),
    "energy_contact_J": ("J", "energy dissipated by the contact per forcing period"),
    "energy_viscous_J": ("J", "energy dissipated by the viscous damper per forcing period"),
    "work_force_J": ("J", "work of the external force per forcing period"),
}
#: integer result variables
INT_VARIABLES = {
    "periods": ("1", "forcing periods integrated for this point"),
    "period_multiple": ("1", "the steady response repeats after this many forcing periods (0 if none)"),
}
_DIRECTIONS = ("up", "down")
_OVERRIDES = ("m", "k", "kt", "mu", "n0")


def status_name(code: int) -> str:
    """Name of a status code of the ``status`` variable."""
    code = int(code)
    if 0 <= code < len(config.SWEEP_STATUS):
        return config.SWEEP_STATUS[code]
    return "not-computed"


def default_workers() -> int:
    """Number of local cores usable by this process."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


@dataclass(frozen=True)
class LineSpec:
    """One sweep line: everything that determines its result.

    Attributes
    ----------
    eta : float
        N1 / N0.
    beta : float or None
        mu N0 / F1 (None when ``f1`` is given).
    f1 : float or None
        Forcing amplitude F1, N (None when ``beta`` is given).
    delta_deg : float
        Phase of the normal load, degrees.
    direction : str
        ``up`` (gamma increasing) or ``down``.
    gammas : tuple of float
        Grid, increasing (the line visits it in its direction).
    model, law_params, zeta, overrides, steps_per_period
        Contact law name, its law-specific parameters as the canonical
        ``((name, value), ...)`` of :func:`jointdyn.laws.canonical_law_params`,
        viscous damping ratio, paper parameter overrides as
        ``((name, value), ...)``, integration steps per forcing period (None:
        solver default).
    """

    eta: float
    beta: float | None
    f1: float | None
    delta_deg: float
    direction: str
    gammas: tuple
    model: str = config.MODEL
    law_params: tuple = ()
    zeta: float = 0.0
    overrides: tuple = ()
    steps_per_period: int | None = None

    def to_json(self) -> str:
        """Canonical JSON (exact floats via repr) used for resume checks."""
        d = asdict(self)
        d["gammas"] = [repr(float(g)) for g in self.gammas]
        d["overrides"] = [[k, repr(float(v))] for k, v in self.overrides]
        d["law_params"] = [[k, repr(v) if isinstance(v, float) else v] for k, v in self.law_params]
        for key in ("eta", "beta", "f1", "delta_deg", "zeta"):
            if d[key] is not None:
                d[key] = repr(float(d[key]))
        return json.dumps(d, sort_keys=True)

    @property
    def key(self) -> str:
        """File stem of the line: readable prefix plus a hash of the full spec."""
        h = hashlib.sha1(self.to_json().encode()).hexdigest()[:12]
        load = f"beta{self.beta:g}" if self.beta is not None else f"f1{self.f1:g}N"
        return f"eta{self.eta:g}_{load}_delta{self.delta_deg:g}_{self.direction}_{h}"

    def system(self):
        """The :class:`~jointdyn.systems.System` of this line."""
        from ..systems import System

        return System.paper_damper(
            eta=self.eta,
            beta=1.0 if self.beta is None else self.beta,
            f1=self.f1,
            delta_deg=self.delta_deg,
            model=self.model,
            zeta=self.zeta,
            law_params=dict(self.law_params),
            **dict(self.overrides),
        )


def _steady_state_fn():
    """The time-domain steady-state solver (resolved late; tests may swap it)."""
    from ..dynamics import steady_state

    return steady_state


def _solve_line(spec: LineSpec) -> dict:
    """Sweep one line; returns arrays on the increasing gamma grid.

    Each point starts from the previous point's steady state (``restart``);
    after an ``unbounded`` point the next starts from the linear estimate.

    Returns
    -------
    dict
        ``status`` (int8 codes), every name of :data:`VARIABLES` (float64)
        and :data:`INT_VARIABLES` (int32), each of length ``len(gammas)``.
    """
    solve = _steady_state_fn()
    system = spec.system()
    g = np.asarray(spec.gammas, dtype=float)
    m = g.size
    out = {name: np.full(m, np.nan) for name in VARIABLES}
    out.update({name: np.zeros(m, dtype=np.int32) for name in INT_VARIABLES})
    out["status"] = np.full(m, _MISSING, dtype=np.int8)
    order = range(m) if spec.direction == "up" else range(m - 1, -1, -1)
    kwargs = {"keep_loop": False}
    if spec.steps_per_period is not None:
        kwargs["steps_per_period"] = spec.steps_per_period
    prev = None
    for i in order:
        res = solve(system, float(g[i]), start=prev, **kwargs)
        if res.status not in STATUS_CODES:
            raise RuntimeError(f"steady_state returned unknown status {res.status!r}")
        out["status"][i] = STATUS_CODES[res.status]
        for name in VARIABLES:
            out[name][i] = float(getattr(res, name, np.nan))
        out["periods"][i] = int(res.periods)
        out["period_multiple"][i] = int(getattr(res, "period_multiple", 0) or 0)
        prev = None if res.status == "unbounded" else res
    return out


def _line_dataset(spec: LineSpec, res: dict):
    """One finished line as a small Dataset (dim gamma) carrying its spec."""
    import xarray as xr

    data = {name: ("gamma", res[name]) for name in (*VARIABLES, *INT_VARIABLES, "status")}
    return xr.Dataset(data, coords={"gamma": np.asarray(spec.gammas, float)}, attrs={"spec": spec.to_json()})


def _write_line(path: Path, ds) -> None:
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="scipy")


def _read_line(path: Path, spec: LineSpec) -> dict | None:
    """Arrays of a saved line if it exists and was made from ``spec``."""
    import xarray as xr

    if not path.is_file():
        return None
    try:
        with xr.open_dataset(path, engine="scipy") as ds:
            if ds.attrs.get("spec") != spec.to_json():
                return None
            return {
                name: np.asarray(ds[name].values).astype(
                    np.int8 if name == "status" else (np.int32 if name in INT_VARIABLES else np.float64)
                )
                for name in (*VARIABLES, *INT_VARIABLES, "status")
            }
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _iter_results(todo, client, n_workers, pool):
    """Yield ``(index, result)`` for the lines ``todo`` as they finish."""
    if not todo:
        return
    if client is not None:
        from distributed import as_completed

        futures = client.map(_solve_line, [s for _, s in todo], pure=False)
        index = {f.key: i for f, (i, _) in zip(futures, todo)}
        for fut in as_completed(futures):
            yield index[fut.key], fut.result()
        return
    if n_workers <= 1 or len(todo) == 1:
        for i, spec in todo:
            yield i, _solve_line(spec)
        return
    import concurrent.futures as cf

    if pool == "thread":
        ex = cf.ThreadPoolExecutor(max_workers=n_workers)
    else:
        import multiprocessing as mp

        # fork (Linux): workers inherit the compiled kernels and do not
        # re-import the caller's __main__ (spawn would, breaking scripts
        # without a main guard); spawn elsewhere
        method = "fork" if "fork" in mp.get_all_start_methods() else "spawn"
        ex = cf.ProcessPoolExecutor(max_workers=n_workers, mp_context=mp.get_context(method))
    with ex:
        futs = {ex.submit(_solve_line, spec): i for i, spec in todo}
        try:
            for fut in cf.as_completed(futs):
                yield futs[fut], fut.result()
        finally:
            for f in futs:
                f.cancel()


def _floats(name, values, check):
    if values is None:
        raise ValueError(f"{name} must be a non-empty list of numbers")
    arr = np.atleast_1d(np.asarray(values, dtype=object))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D list of numbers")
    out = [check(name, v) for v in arr]
    if len(set(out)) != len(out):
        raise ValueError(f"{name} must not contain duplicates, got {list(out)}")
    return out


def _check_inputs(gammas, etas, betas, f1s, deltas, directions, model, law_params, zeta, overrides,
                  steps_per_period):
    from ..laws import canonical_law_params, law_names

    g = _floats("gamma", gammas, V.positive)
    g = tuple(sorted(g))
    etas = _floats("eta", etas, V.nonnegative)
    if betas is not None and f1s is not None:
        raise ValueError("give either beta (mu N0 / F1) or f1 (forcing amplitude, N), not both")
    if f1s is not None:
        f1s = _floats("f1", f1s, V.positive)
        betas = None
    else:
        betas = _floats("beta", (1.0,) if betas is None else betas, V.positive)
    deltas = _floats("delta", deltas, V.finite)
    if isinstance(directions, str):
        directions = (directions,)
    directions = list(directions)
    if not directions:
        raise ValueError("direction must be a non-empty list of up, down")
    for d in directions:
        V.choice("direction", d, _DIRECTIONS)
    if len(set(directions)) != len(directions):
        raise ValueError(f"direction must not contain duplicates, got {directions}")
    V.choice("model", model, law_names())
    law_params = canonical_law_params(model, law_params)
    zeta = V.nonnegative("zeta", zeta)
    ov = []
    for key in _OVERRIDES:
        val = overrides.get(key)
        if val is None:
            continue
        val = V.positive(key, val)
        ov.append((key, val))
    if steps_per_period is not None:
        steps_per_period = V.positive_int("steps_per_period", steps_per_period, 8)
    return g, etas, betas, f1s, deltas, directions, model, law_params, zeta, tuple(ov), steps_per_period


def _check_client(client) -> None:
    """``client`` is None or a connected ``distributed.Client``."""
    if client is None:
        return
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - dask[distributed] is a dependency
        Client = None
    if Client is None or not isinstance(client, Client):
        raise ValueError(
            "client must be a distributed.Client (connect first: distributed.Client('tcp://host:8786')) "
            f"or None for local workers, got {type(client).__name__} {client!r:.80}"
        )


def frc_sweep(
    gammas,
    *,
    etas=(0.5,),
    betas=None,
    f1s=None,
    deltas=(0.0,),
    directions=("up", "down"),
    model: str = config.MODEL,
    law_params: dict | None = None,
    n: int | None = None,
    zeta: float = 0.0,
    m: float | None = None,
    k: float | None = None,
    kt: float | None = None,
    mu: float | None = None,
    n0: float | None = None,
    steps_per_period: int | None = None,
    client=None,
    n_workers: int | None = None,
    out=None,
    progress: bool = True,
    on_line=None,
):
    """Steady-state frequency response of the paper's damper on a parameter grid.

    Solves MODEL.md section 6, ``m x'' + c x' + k x = F1 sin(w t) - T(x, N(t))``,
    ``N = N0 (1 + eta sin(w t + delta))``, for every combination of the groups
    and ``gamma = w / sqrt(k/m)``, sweeping gamma up and/or down with warm
    starts (see the module docstring).

    Parameters
    ----------
    gammas : sequence of float
        Frequency ratios (> 0, distinct; any order, stored increasing).
    etas : sequence of float
        N1 / N0 (>= 0).
    betas : sequence of float, optional
        mu N0 / F1 (> 0); default ``(1.0,)``. Not together with ``f1s``.
    f1s : sequence of float, optional
        Forcing amplitudes F1 in N (> 0), instead of ``betas``.
    deltas : sequence of float
        Normal-load phase, **degrees**.
    directions : sequence of {"up", "down"}
        Sweep directions.
    model : str
        Contact law, one of :func:`jointdyn.laws.law_names` (default
        ``iwan``, the exact Iwan model, ``config.MODEL``).
    law_params : dict, optional
        Law-specific parameters of ``model``
        (:func:`jointdyn.laws.law_parameters`), e.g. ``{"n": 200}``.
    n : int, optional
        Shorthand for ``law_params={"n": n}`` (elements of ``discrete``);
        a model without that parameter refuses it.
    zeta : float
        Viscous damping ratio (paper: 0).
    m, k, kt, mu, n0 : float, optional
        Overrides of the paper values (kg, N/m, N/m, -, N).
    steps_per_period : int, optional
        Integration steps per forcing period (solver default if None).
    client : distributed.Client, optional
        Run the lines on this Dask cluster (a connected client, not an
        address).
    n_workers : int, optional
        Local parallel workers (default: all usable cores; 1 runs serially
        in this process).
    out : path, optional
        Directory for resumable per-line files and the final ``frc.nc`` and
        ``frc.csv`` (all written atomically); checked for writability before
        anything is computed.
    progress : bool
        Show a tqdm bar over points (hidden when not a terminal).
    on_line : callable, optional
        ``on_line(spec, computed)`` after each line is stored; ``computed``
        is False for a line loaded from ``out``.

    Returns
    -------
    xarray.Dataset
        Dims ``(eta, beta, delta, direction, gamma)`` (``f1`` instead of
        ``beta`` when ``f1s`` is given). Variables: see :data:`VARIABLES`
        and :data:`INT_VARIABLES`, plus ``status`` (int8; legend in its
        ``legend`` attribute). Only points with status 0 (periodic) carry a
        steady amplitude; the others hold the solver's last values.

    Raises
    ------
    ValueError
        Bad input (names the parameter and the allowed range).
    """
    from tqdm import tqdm

    law_params = dict(law_params or {})
    if n is not None:
        if "n" in law_params:
            raise ValueError("n is given twice: as n and in law_params; give it once")
        law_params["n"] = n
    g, etas, betas, f1s, deltas, directions, model, law_params, zeta, ov, spp = _check_inputs(
        gammas, etas, betas, f1s, deltas, directions, model, law_params, zeta,
        dict(m=m, k=k, kt=kt, mu=mu, n0=n0), steps_per_period,
    )
    if n_workers is not None:
        n_workers = V.positive_int("n_workers", n_workers)
    _check_client(client)
    if out is not None:  # before computing: no finished line is lost to an unwritable out
        V.output_dir("out", out, files=("frc.nc", "frc.csv"), subdirs=("lines",))
    load_name, loads = ("beta", betas) if f1s is None else ("f1", f1s)
    if load_name == "beta" and dict(ov).get("mu", 0.5) <= 0:
        raise ValueError("mu must be > 0 when sweeping beta = mu N0 / F1")

    specs = []
    for ie, eta in enumerate(etas):
        for il, load in enumerate(loads):
            for idl, delta in enumerate(deltas):
                for idr, direction in enumerate(directions):
                    spec = LineSpec(
                        eta=eta,
                        beta=load if load_name == "beta" else None,
                        f1=load if load_name == "f1" else None,
                        delta_deg=delta,
                        direction=direction,
                        gammas=g,
                        model=model,
                        law_params=law_params,
                        zeta=zeta,
                        overrides=ov,
                        steps_per_period=spp,
                    )
                    specs.append(((ie, il, idl, idr), spec))

    shape = (len(etas), len(loads), len(deltas), len(directions), len(g))
    arrays = {name: np.full(shape, np.nan) for name in VARIABLES}
    arrays.update({name: np.zeros(shape, dtype=np.int32) for name in INT_VARIABLES})
    arrays["status"] = np.full(shape, _MISSING, dtype=np.int8)

    line_dir = None if out is None else Path(out) / "lines"
    bar = tqdm(total=len(specs) * len(g), desc="frc", unit="pt", disable=None if progress else True)

    def store(idx, spec, res, computed):
        for name in arrays:
            arrays[name][idx] = res[name]
        bar.update(len(g))
        if on_line is not None:
            on_line(spec, computed)

    todo = []
    for idx, spec in specs:
        res = None if line_dir is None else _read_line(line_dir / f"{spec.key}.nc", spec)
        if res is None:
            todo.append((idx, spec))
        else:
            store(idx, spec, res, False)
    by_idx = dict(todo)
    workers = default_workers() if n_workers is None else n_workers
    try:
        for idx, res in _iter_results(todo, client, workers, config.SWEEP_POOL):
            spec = by_idx[idx]
            if line_dir is not None:
                _write_line(line_dir / f"{spec.key}.nc", _line_dataset(spec, res))
            store(idx, spec, res, True)
    finally:
        bar.close()

    ds = _assemble(arrays, etas, load_name, loads, deltas, directions, g, model, law_params, zeta, ov, spp)
    if out is not None:
        write_outputs(ds, out)
    return ds


def _assemble(arrays, etas, load_name, loads, deltas, directions, g, model, law_params, zeta, ov, spp):
    import xarray as xr

    from ..systems import PAPER

    dims = ("eta", load_name, "delta", "direction", "gamma")
    p = dict(PAPER)
    p.update(dict(ov))
    fy = p["mu"] * p["n0"]
    data = {}
    for name, (unit, desc) in {**VARIABLES, **INT_VARIABLES}.items():
        data[name] = (dims, arrays[name], {"units": unit, "long_name": desc})
    data["status"] = (
        dims,
        arrays["status"],
        {
            "legend": _LEGEND,
            "flag_values": np.arange(len(config.SWEEP_STATUS), dtype=np.int8),
            "flag_meanings": " ".join(config.SWEEP_STATUS),
            "missing_code": _MISSING,
        },
    )
    coords = {
        "eta": ("eta", np.asarray(etas, float), {"long_name": "N1 / N0"}),
        load_name: (
            load_name,
            np.asarray(loads, float),
            {"long_name": "mu N0 / F1"} if load_name == "beta" else {"long_name": "forcing amplitude F1", "units": "N"},
        ),
        "delta": ("delta", np.asarray(deltas, float), {"long_name": "normal-load phase", "units": "deg"}),
        "direction": ("direction", np.asarray(directions, dtype="U4")),
        "gamma": ("gamma", np.asarray(g, float), {"long_name": "w / sqrt(k/m)"}),
    }
    if load_name == "beta":
        coords["f1"] = ("beta", fy / np.asarray(loads, float), {"units": "N", "long_name": "forcing amplitude F1"})
    else:
        coords["beta"] = ("f1", fy / np.asarray(loads, float), {"long_name": "mu N0 / F1"})
    attrs = {
        "title": "steady-state frequency response of the friction damper (MODEL.md section 6)",
        "model": model,
        **{f"law_param_{key}": val for key, val in law_params},
        "zeta": float(zeta),
        "steps_per_period": int(spp) if spp is not None else "solver default",
        "fy_N": float(fy),
        "w0_rad_s": math.sqrt(p["k"] / p["m"]),
        **{f"{key}": float(val) for key, val in p.items()},
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def to_frame(ds):
    """Tidy long table of a sweep Dataset (one row per point) with a
    ``status_name`` column."""
    names = [v for v in ds.data_vars]
    df = ds[names].to_dataframe().reset_index()
    df["status_name"] = [status_name(c) for c in df["status"]]
    return df


def write_outputs(ds, out) -> list[Path]:
    """Write ``frc.nc`` (netCDF3, scipy engine) and ``frc.csv`` atomically."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    nc = out / "frc.nc"
    with atomic_path(nc) as tmp:
        ds.to_netcdf(tmp, engine="scipy")
    csv = out / "frc.csv"
    with atomic_path(csv) as tmp:
        to_frame(ds).to_csv(tmp, index=False)
    return [nc, csv]
