"""Frequency-response sweeps of any System, and of the paper damper's grid.

:func:`frc_sweep` computes time-domain steady states
(:func:`jointdyn.dynamics.steady_state`) over a grid of excitation
frequencies ``gamma = w / w0`` (``w0`` the System's reference frequency)
for

- one :class:`~jointdyn.System` (Dataset dims ``direction, gamma``),
- a mapping of labelled Systems (dims ``system, direction, gamma``),
- the paper damper (docs/model.md section 6) on a grid of its groups ``eta =
  N1/N0``, ``beta = mu N0 / F1`` (or the forcing ``F1`` in N) and ``delta``:
  every grid point is ``System.paper_damper(...)`` (dims ``eta, beta, delta,
  direction, gamma``).

Sweep lines
-----------
Points along gamma are chained: in an ``up`` sweep every point starts from
the steady state of the previous (lower) gamma, in a ``down`` sweep from the
next higher one, so that jumps and coexisting states of the nonlinear
response show as a difference between the two directions. After an
``unbounded`` point the next one restarts from the solver's linear estimate.
A line (one System, one direction) runs as consecutive chunks of
``SweepOptions.chunk_points`` points, each continuing from the previous
chunk's last state; lines run side by side on a local process or thread
pool or on a Dask cluster (``_pool.py``), and the result depends neither on
where nor in which order they ran, nor on the chunking.

Resume
------
With ``out=DIR`` every finished chunk is written atomically under
``DIR/lines`` (``_checkpoint.py``) with its resume key: the line's spec (the
System's fingerprint, direction, grid, steps, outputs), the solver's results
version (:data:`jointdyn.dynamics.version.SOLVER_VERSION`) and the jointdyn
version. A rerun reuses every checkpoint whose key matches and computes the
rest, continuing each line from its last saved state; checkpoints of another
solver version are recomputed, never reused. An interrupt (Ctrl-C) stops
every chunk after its current point and saves what finished. The assembled
Dataset goes to ``DIR/frc.nc`` and a tidy CSV ``DIR/frc.csv``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import config
from .._io import write_dataset
from ..dynamics.status import SteadyStatus
from ..laws import STATE_NAMES
from . import _points
from ._checkpoint import load_line, save_chunk
from ._family import LineSpec, fingerprint, paper_family, system_family
from ._points import (
    CONTACT_VARIABLES,
    DOF_VARIABLES,
    INT_VARIABLES,
    NOT_COMPUTED,
    NOT_COMPUTED_NAME,
    PAIR_VARIABLES,
    STATE_VARIABLE,
    STATUS_CODES,
    VARIABLES,
    ChunkTask,
    empty_arrays,
)
from .options import SweepOptions

__all__ = [
    "frc_sweep",
    "SweepOptions",
    "LineSpec",
    "STATUS_CODES",
    "NOT_COMPUTED",
    "NOT_COMPUTED_NAME",
    "VARIABLES",
    "INT_VARIABLES",
    "DOF_VARIABLES",
    "CONTACT_VARIABLES",
    "PAIR_VARIABLES",
    "RUN_ATTRIBUTES",
    "status_name",
    "to_frame",
    "write_outputs",
    "default_workers",
]

_LEGEND = ", ".join(f"{s.code}: {s.value}" for s in SteadyStatus) + f", {NOT_COMPUTED}: {NOT_COMPUTED_NAME}"
_DIRECTIONS = ("up", "down")
#: keyword arguments that describe the paper damper's grid (not a System's)
_PAPER_KEYS = ("etas", "betas", "f1s", "deltas", "model", "law_params", "n", "zeta", "m", "k", "kt", "mu", "n0")
#: Dataset attributes about a run rather than its results (not written to frc.nc)
RUN_ATTRIBUTES = ("reused_points", "stale_points")


def status_name(code: int) -> str:
    """Name of a status code of the ``status`` variable."""
    code = int(code)
    if 0 <= code < len(SteadyStatus):
        return SteadyStatus.from_code(code).value
    return NOT_COMPUTED_NAME


def default_workers() -> int:
    """Number of local cores usable by this process."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


class _LineRun:
    """One line during a sweep: its spec, where it stands, its results so far."""

    def __init__(self, index, spec, system_index, system, ncontacts, dofs, where="", npairs=0):
        self.index = index
        self.where = where
        self.spec = spec
        self.system_index = system_index
        self.rdof = int(system.response_dof)
        self.ncontacts = ncontacts
        self.npairs = npairs
        self.dofs = dofs
        g = list(spec.gammas)
        self.gammas = tuple(g if spec.direction == "up" else g[::-1])
        self.arrays = empty_arrays(len(g), len(dofs), ncontacts, spec.loop_outputs, npairs)
        self.next = 0
        self.start = None

    @property
    def finished(self) -> bool:
        """Every point of the line is computed or loaded."""
        return self.next >= len(self.gammas)

    def next_task(self, points: int) -> ChunkTask:
        """The task of the next ``points`` points of the line."""
        stop = min(self.next + points, len(self.gammas))
        return ChunkTask(line=self.index, system_index=self.system_index, first=self.next,
                         gammas=self.gammas[self.next:stop], start=self.start, rdof=self.rdof, dofs=self.dofs,
                         ncontacts=self.ncontacts, loop_outputs=self.spec.loop_outputs,
                         steps_per_period=self.spec.steps_per_period, where=self.where, npairs=self.npairs,
                         steady=self.spec.steady)

    def accept(self, chunk) -> None:
        """Store a chunk that starts where the line stands."""
        if chunk.first != self.next:
            raise RuntimeError(f"chunk at position {chunk.first} of a line standing at {self.next}")
        for name, a in chunk.arrays.items():
            self.arrays[name][chunk.first:chunk.first + chunk.done] = a
        self.next += chunk.done
        self.start = chunk.restart

    def on_grid(self) -> dict:
        """The results on the increasing gamma grid."""
        return {name: (a if self.spec.direction == "up" else a[::-1]) for name, a in self.arrays.items()}


def _family(system_or_grid, gammas, paper: dict):
    """(family, gamma grid) of either call form; ValueError naming misplaced keywords."""
    from ..systems import System

    if isinstance(system_or_grid, (System, Mapping)):
        given = [k for k in _PAPER_KEYS if paper.get(k) is not None]
        if given:
            raise ValueError(f"{', '.join(given)} describe the paper damper's grid (frc_sweep(gammas, etas=...)); "
                             "a System sweep takes every parameter from its System(s)")
        if gammas is None:
            raise ValueError("gammas must be given: frc_sweep(system, gammas)")
        return system_family(system_or_grid), gammas
    if gammas is not None:
        raise ValueError("gammas is given twice: frc_sweep(gammas, ...) sweeps the paper damper's grid, "
                         "frc_sweep(system, gammas) a System")
    law_params = dict(paper.get("law_params") or {})
    if paper.get("n") is not None:
        if "n" in law_params:
            raise ValueError("n is given twice: as n and in law_params; give it once")
        law_params["n"] = paper["n"]
    fam = paper_family(etas=paper.get("etas"), betas=paper.get("betas"), f1s=paper.get("f1s"),
                       deltas=paper.get("deltas"), model=config.MODEL if paper.get("model") is None else paper["model"],
                       law_params=law_params, zeta=0.0 if paper.get("zeta") is None else paper["zeta"],
                       overrides={k: paper.get(k) for k in ("m", "k", "kt", "mu", "n0")})
    return fam, system_or_grid


def _check_steps(family, grid, spp, lines: int, march=None) -> None:
    """The steps of a forcing period at the lowest gamma (the most) of every System fit the memory bound
    for ``lines`` lines run at once (:func:`jointdyn.dynamics.check_period_steps` with the points' march
    ``march``, None: the defaults): refused before anything is computed, not point by point."""
    from ..dynamics import check_period_steps

    for _, label, system in family.entries:
        try:
            check_period_steps(system, float(min(grid)) * system.w0, spp, march=march, lines=lines)
        except ValueError as exc:
            raise ValueError(f"system {label!r}: {exc}" if len(family.entries) > 1 else str(exc)) from None


def _grid(gammas) -> tuple:
    if gammas is None or isinstance(gammas, (str, bytes)):
        raise ValueError(f"gamma must be a non-empty list of numbers, got {gammas!r:.60}")
    arr = np.atleast_1d(np.asarray(gammas, dtype=object))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError("gamma must be a non-empty 1-D list of numbers")
    g = [V.positive("gamma", v) for v in arr]
    if len(set(g)) != len(g):
        raise ValueError(f"gamma must not contain duplicates, got {g}")
    return tuple(sorted(g))


def _directions(directions) -> list:
    if isinstance(directions, str):
        directions = (directions,)
    directions = list(directions)
    if not directions:
        raise ValueError("direction must be a non-empty list of up, down")
    for d in directions:
        V.choice("direction", d, _DIRECTIONS)
    if len(set(directions)) != len(directions):
        raise ValueError(f"direction must not contain duplicates, got {directions}")
    return directions


def _dofs(dofs, family) -> tuple:
    """Requested DOFs (default: the response DOFs of the family), checked against every System."""
    systems = [s for _, _, s in family.entries]
    if dofs is None:
        return tuple(sorted({int(s.response_dof) for s in systems}))
    arr = list(np.atleast_1d(np.asarray(dofs, dtype=object)))
    if not arr:
        raise ValueError("dofs must be a non-empty list of DOF indices")
    out = tuple(V.positive_int("dofs", d, 0) for d in arr)
    nmin = min(s.ndof for s in systems)
    bad = [d for d in out if d >= nmin]
    if bad:
        raise ValueError(f"dofs must be in [0, {nmin - 1}] (DOFs of every System), got {bad[0]}")
    if len(set(out)) != len(out):
        raise ValueError(f"dofs must not contain duplicates, got {list(out)}")
    return out


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


def _executor(family, client, n_workers, nlines, on_point, opt: SweepOptions):
    from ._pool import DaskExecutor, LocalExecutor, SerialExecutor

    systems = tuple(s for _, _, s in family.entries)
    if client is not None:
        return DaskExecutor(systems, client, opt.tasks_per_worker)
    workers = default_workers() if n_workers is None else n_workers
    if workers <= 1 or nlines == 1:
        return SerialExecutor(systems, on_point=on_point)
    if opt.pool == "process":
        _prepare_kernels(systems)
    return LocalExecutor(systems, min(workers, nlines), opt.pool, opt.tasks_per_worker)


def _prepare_kernels(systems) -> None:
    """Compile the steady-state kernels here before a process pool forks (its
    workers inherit them instead of each compiling the same at once); not
    when tests swapped the solver."""
    from ..dynamics import prepare_kernels, steady_state

    if _points._steady_state_fn() is steady_state:
        prepare_kernels(systems)


def _line_runs(family, directions, g, spp, dofs, loop_outputs, steady=None) -> list:
    nc = max((len(s.contacts) for _, _, s in family.entries), default=0)
    npairs = max((_npairs(s) for _, _, s in family.entries), default=0)
    runs = []
    for i, (_, label, system) in enumerate(family.entries):
        key = fingerprint(system)
        for d in directions:
            spec = LineSpec(label=label, system=key, direction=d, gammas=g, steps_per_period=spp, dofs=dofs,
                            loop_outputs=loop_outputs, steady=steady)
            where = f"system {label!r}: " if family.dims else ""
            runs.append(_LineRun(len(runs), spec, i, system, nc, dofs, where, npairs))
    return runs


def _npairs(system) -> int:
    """Node pairs of all the interfaces of ``system``."""
    return sum(int(itf.pairs.shape[0]) for itf in system.interfaces)


def frc_sweep(
    system_or_grid,
    gammas=None,
    *,
    etas=None,
    betas=None,
    f1s=None,
    deltas=None,
    directions=("up", "down"),
    model: str | None = None,
    law_params: dict | None = None,
    n: int | None = None,
    zeta: float | None = None,
    m: float | None = None,
    k: float | None = None,
    kt: float | None = None,
    mu: float | None = None,
    n0: float | None = None,
    dofs=None,
    loop_outputs: bool | None = None,
    steps_per_period: int | None = None,
    client=None,
    n_workers: int | None = None,
    out=None,
    progress: bool = True,
    on_line=None,
    options: SweepOptions | None = None,
):
    """Steady-state frequency response of a System, of labelled Systems, or of
    the paper damper on a grid of its groups.

    Two call forms:

    - ``frc_sweep(system, gammas, ...)``: ``system`` is a
      :class:`~jointdyn.System` or a mapping ``{label: System}``;
    - ``frc_sweep(gammas, etas=..., betas=..., ...)``: the paper damper
      (docs/model.md section 6, ``m x'' + c x' + k x = F1 sin(w t) - T(x, N(t))``,
      ``N = N0 (1 + eta sin(w t + delta))``) on the grid of ``etas`` x
      ``betas`` (or ``f1s``) x ``deltas``, each point ``System.paper_damper``.

    Each System is swept in ``gamma = w / w0`` (``w0 = system.w0``) up and/or
    down with warm starts (see the module docstring).

    Parameters
    ----------
    system_or_grid : System, mapping of str to System, or sequence of float
        The System(s) to sweep, or the gamma grid of the paper damper form.
    gammas : sequence of float, optional
        Frequency ratios (> 0, distinct; any order, stored increasing) of
        the System form.
    etas : sequence of float
        Paper form: N1 / N0 (>= 0); default ``(0.5,)``.
    betas : sequence of float, optional
        Paper form: mu N0 / F1 (> 0); default ``(1.0,)``. Not with ``f1s``.
    f1s : sequence of float, optional
        Paper form: forcing amplitudes F1 in N (> 0), instead of ``betas``.
    deltas : sequence of float
        Paper form: normal-load phase, **degrees**; default ``(0.0,)``.
    directions : sequence of {"up", "down"}
        Sweep directions.
    model : str
        Paper form: contact law, one of :func:`jointdyn.laws.law_names`
        (default ``iwan``, the exact Iwan model, ``config.MODEL``).
    law_params : dict, optional
        Paper form: law-specific parameters of ``model``
        (:func:`jointdyn.laws.law_parameters`), e.g. ``{"n": 200}``.
    n : int, optional
        Paper form: shorthand for ``law_params={"n": n}``.
    zeta : float
        Paper form: viscous damping ratio (default 0, the paper's).
    m, k, kt, mu, n0 : float, optional
        Paper form: overrides of the paper values (kg, N/m, N/m, -, N).
    dofs : sequence of int, optional
        DOFs whose amplitude and offset are recorded per point (variables
        with dimension ``dof``); default: the response DOF of each System.
    loop_outputs : bool, optional
        Record the per-DOF and per-contact variables (from the steady
        period, kept for it: about one more forcing period per point).
        Default: True for the System form, False for the paper form (whose
        Dataset keeps its layout and cost unless asked).
    steps_per_period : int, optional
        Integration steps per forcing period (solver default if None).
    client : distributed.Client, optional
        Run on this Dask cluster (a connected client, not an address).
    n_workers : int, optional
        Local parallel workers (default: all usable cores; 1 runs serially
        in this process).
    out : path, optional
        Directory for the resume checkpoints (``lines/``) and the final
        ``frc.nc`` and ``frc.csv`` (all written atomically); checked for
        writability before anything is computed.
    progress : bool
        Show a tqdm bar over points (hidden when not a terminal); it moves
        per point and says how many points a resume reused.
    on_line : callable, optional
        ``on_line(spec, computed)`` after each line is complete; ``computed``
        is False for a line loaded entirely from ``out``.
    options : SweepOptions, optional
        How the lines run (chunks, the local pool, the queue, the progress refresh; default
        ``SweepOptions()``); none of it changes a result but its ``steady``, the numbers of every
        point's steady state (:class:`~jointdyn.dynamics.options.SteadyStateOptions`).

    Returns
    -------
    xarray.Dataset
        Dims: the family's (none, ``system``, or ``eta, beta, delta`` with
        ``f1`` for ``beta`` when ``f1s`` is given), then ``direction,
        gamma``. Variables: :data:`VARIABLES` (response DOF, first
        contact's q), :data:`INT_VARIABLES`, ``status`` (int8; legend in its
        ``legend`` attribute); with ``loop_outputs`` also
        :data:`DOF_VARIABLES` (dim ``dof``), :data:`CONTACT_VARIABLES` (dim
        ``contact``) and ``state_fraction`` (dims ``contact, state``);
        with interfaces :data:`PAIR_VARIABLES` (dim ``pair``: energy per
        period and stick, slip, open fractions of every node pair).
        Only points with status 0 (periodic) carry steady values. Attribute
        ``reused_points``: points loaded from ``out``; ``stale_points``:
        points of checkpoints of another solver version, recomputed.

    Raises
    ------
    ValueError
        Bad input (names the parameter and the allowed range); a solver's
        refusal of a System (raised as the solver words it, after
        ``system 'label': `` in a family of Systems; the points finished
        before it are saved under ``out``).
    """
    paper = dict(etas=etas, betas=betas, f1s=f1s, deltas=deltas, model=model, law_params=law_params, n=n,
                 zeta=zeta, m=m, k=k, kt=kt, mu=mu, n0=n0)
    family, gammas = _family(system_or_grid, gammas, paper)
    g = _grid(gammas)
    directions = _directions(directions)
    spp = None if steps_per_period is None else V.positive_int("steps_per_period", steps_per_period, 8)
    if n_workers is not None:
        n_workers = V.positive_int("n_workers", n_workers)
    _check_client(client)
    opt = SweepOptions() if options is None else options
    if not isinstance(opt, SweepOptions):
        raise ValueError(f"options must be a SweepOptions, got {type(opt).__name__}")
    march = None if opt.steady is None else opt.steady.march
    _check_steps(family, g, spp, 1 if len(directions) == 1 or n_workers == 1 else 2, march)
    dofs = _dofs(dofs, family)
    loop_outputs = (not family.dims or family.dims == ("system",)) if loop_outputs is None else bool(loop_outputs)
    if out is not None:  # before computing: no finished chunk is lost to an unwritable out
        V.output_dir("out", out, files=("frc.nc", "frc.csv"), subdirs=("lines",))
    runs = _line_runs(family, directions, g, spp, dofs, loop_outputs, opt.steady)
    reused, stale = _run(runs, family, client, n_workers, out, progress, on_line, opt)
    ds = _assemble(family, runs, directions, g, dofs, spp, loop_outputs)
    if opt.steady is not None:
        ds.attrs["steady_options"] = repr(opt.steady)
    ds.attrs["reused_points"] = int(reused)
    ds.attrs["stale_points"] = int(stale)
    if out is not None:
        write_outputs(ds, out)
    return ds


def _resume(runs, line_root) -> tuple:
    """Load the checkpoints of every line; returns (reused, stale) point counts."""
    reused = stale = 0
    if line_root is None:
        return 0, 0
    names = tuple(runs[0].arrays) if runs else ()
    for run in runs:
        ck = load_line(line_root / run.spec.folder, run.spec.resume_key(), names, run.index, run.gammas)
        for chunk in ck.chunks:
            run.accept(chunk)
        reused += ck.reused
        stale += ck.stale
    return reused, stale


def _run(runs, family, client, n_workers, out, progress, on_line, opt: SweepOptions) -> tuple:
    """Resume, then compute the rest; returns (reused, stale) point counts."""
    from tqdm import tqdm

    from ._pool import run_chunks

    line_root = None if out is None else Path(out) / "lines"
    reused, stale = _resume(runs, line_root)
    total = sum(len(r.gammas) for r in runs)
    bar = tqdm(total=total, initial=reused, desc="frc", unit="pt", disable=None if progress else True)
    if reused:
        bar.set_postfix_str(f"reused {reused}")
    for run in runs:
        if run.finished and on_line is not None:
            on_line(run.spec, False)
    state = {"shown": reused}

    def show():
        now = reused + executor.progress()
        if now > state["shown"]:
            bar.update(now - state["shown"])
            state["shown"] = now

    def on_chunk(run, chunk):
        if line_root is not None and chunk.done:
            save_chunk(line_root / run.spec.folder, run.spec.resume_key(), chunk,
                       run.gammas[:chunk.first + chunk.done])
        show()
        if run.finished and on_line is not None:
            on_line(run.spec, True)

    todo = [r for r in runs if not r.finished]
    try:
        if todo:
            executor = _executor(family, client, n_workers, len(todo), show, opt)
            run_chunks(runs, executor, opt.chunk_points, on_chunk, on_poll=show, poll_s=opt.progress_poll_s)
    finally:
        bar.close()
    return reused, stale


def _stack(runs, family, directions, name, shape_tail, dtype, fill):
    arr = np.full((*family.shape, len(directions), *shape_tail), fill, dtype=dtype)
    for run in runs:
        idx = family.entries[run.system_index][0]
        arr[(*idx, directions.index(run.spec.direction))] = run.on_grid()[name]
    return arr


def _assemble(family, runs, directions, g, dofs, spp, loop_outputs):
    import xarray as xr

    from .. import __version__
    from ..dynamics.version import SOLVER_VERSION

    dims = (*family.dims, "direction", "gamma")
    m = len(g)
    data = {}
    for name, (unit, desc) in {**VARIABLES, **INT_VARIABLES}.items():
        dtype = np.int32 if name in INT_VARIABLES else np.float64
        data[name] = (dims, _stack(runs, family, directions, name, (m,), dtype, 0 if name in INT_VARIABLES
                                   else np.nan), {"units": unit, "long_name": desc})
    reasons = config.SWEEP_NOT_SETTLED_REASONS
    data["not_settled_reason"][2].update(flag_values=np.arange(len(reasons), dtype=np.int32),
                                         flag_meanings=" ".join(reasons))
    data["status"] = (dims, _stack(runs, family, directions, "status", (m,), np.int8, NOT_COMPUTED), {
        "legend": _LEGEND,
        "flag_values": np.array([s.code for s in SteadyStatus], dtype=np.int8),
        "flag_meanings": " ".join(s.value for s in SteadyStatus),
        "not_computed_code": NOT_COMPUTED,
        "missing_code": NOT_COMPUTED,  # deprecated duplicate of not_computed_code (CHANGELOG)
    })
    coords = dict(family.coords)
    coords["direction"] = (("direction",), np.asarray(directions, dtype="U4"), {})
    coords["gamma"] = (("gamma",), np.asarray(g, float), {"long_name": "w / w0"})
    if loop_outputs:
        nc = runs[0].ncontacts if runs else 0
        for name, (unit, desc) in DOF_VARIABLES.items():
            data[name] = ((*dims, "dof"), _stack(runs, family, directions, name, (m, len(dofs)), float, np.nan),
                          {"units": unit, "long_name": desc})
        for name, (unit, desc) in CONTACT_VARIABLES.items():
            data[name] = ((*dims, "contact"), _stack(runs, family, directions, name, (m, nc), float, np.nan),
                          {"units": unit, "long_name": desc})
        name, unit, desc = STATE_VARIABLE
        data[name] = ((*dims, "contact", "state"),
                      _stack(runs, family, directions, name, (m, nc, len(STATE_NAMES)), float, np.nan),
                      {"units": unit, "long_name": desc})
        coords["dof"] = (("dof",), np.asarray(dofs, dtype=np.int64), {"long_name": "degree of freedom"})
        coords["contact"] = (("contact",), np.arange(nc, dtype=np.int64), {"long_name": "contact index"})
        coords["state"] = (("state",), np.asarray(STATE_NAMES, dtype=str), {"long_name": "motion state"})
    npairs = runs[0].npairs if runs else 0
    if npairs:  # a slip map per point: every pair of the interfaces, with or without loop outputs
        for name, (unit, desc, _) in PAIR_VARIABLES.items():
            data[name] = ((*dims, "pair"), _stack(runs, family, directions, name, (m, npairs), float, np.nan),
                          {"units": unit, "long_name": desc})
        coords["pair"] = (("pair",), np.arange(npairs, dtype=np.int64),
                          {"long_name": "interface node pair (all interfaces one after the other)"})
    attrs = {"title": "steady-state frequency response (time domain)", **family.attrs,
             "steps_per_period": int(spp) if spp is not None else "solver default",
             "solver_version": int(SOLVER_VERSION), "jointdyn_version": __version__}
    return xr.Dataset(data, coords={k: (d, v, a) for k, (d, v, a) in coords.items()}, attrs=attrs)


def to_frame(ds):
    """Tidy long table of a sweep Dataset: one row per point (the dims of
    ``status``), a ``status_name`` column, and one column per DOF, contact
    and state for the per-DOF and per-contact variables
    (``dof_amplitude_m_dof3``, ``contact_energy_J_c0``,
    ``state_fraction_c0_macroslip``)."""
    point_dims = list(ds["status"].dims)
    flat = [v for v in ds.data_vars if set(ds[v].dims) <= set(point_dims)]
    df = ds[flat].to_dataframe(dim_order=point_dims).reset_index()
    for name in ds.data_vars:
        extra = [d for d in ds[name].dims if d not in point_dims]
        if not extra:
            continue
        stacked = ds[name].stack(_col=extra).transpose(*point_dims, "_col")
        for j, key in enumerate(stacked.indexes["_col"]):
            parts = key if isinstance(key, tuple) else (key,)
            label = "_".join(_column_part(d, p) for d, p in zip(extra, parts))
            df[f"{name}_{label}"] = stacked.isel(_col=j).values.reshape(-1)
    df["status_name"] = [status_name(c) for c in df["status"]]
    if "not_settled_reason" in df:
        reasons = config.SWEEP_NOT_SETTLED_REASONS
        unsettled = SteadyStatus.NOT_SETTLED.code
        df["not_settled_reason_name"] = ["" if s != unsettled else reasons[int(r)] if 0 < int(r) < len(reasons) else ""
                                         for s, r in zip(df["status"], df["not_settled_reason"])]
    return df


def _column_part(dim: str, value) -> str:
    return {"dof": f"dof{value}", "contact": f"c{value}", "pair": f"p{value}"}.get(dim, str(value))


def write_outputs(ds, out) -> list[Path]:
    """Write ``frc.nc`` (netCDF3, scipy engine) and ``frc.csv`` atomically
    (without the run attributes :data:`RUN_ATTRIBUTES`: the files hold the
    results, the same however the run went)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    res = ds.copy()
    for key in RUN_ATTRIBUTES:
        res.attrs.pop(key, None)
    return write_dataset(res, out, "frc", table=to_frame)
