"""The work of a sweep: chunks of consecutive points of a line, and what is
recorded per point.

A chunk is a run of consecutive points of one line in its sweep direction;
each point starts from the previous point's steady state (its ``restart``),
after an ``unbounded`` point from the solver's linear estimate (cold). A
chunk returns the points it finished and the warm start of the next point,
so that a line continues from a checkpoint exactly as it would have run on.

Per point: the steady state's status and scalars (:data:`VARIABLES`,
:data:`INT_VARIABLES`); with ``loop_outputs`` also, from the recorded steady
period (:func:`loop_statistics`), the amplitude and offset of each requested
DOF and per contact the dissipated energy, the mean and extreme normal
force and the fraction of time in each motion state. A system with
interfaces also records, per node pair, the energy it dissipates per period
and the fractions of the period it sticks, slips and is open
(:data:`PAIR_VARIABLES`, from the steady state itself, with or without
``loop_outputs``): the data of a slip map.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field

import numpy as np

from .. import config
from ..dynamics.status import EnergyCheck, SteadyStatus
from ..laws import STATE_NAMES

__all__ = [
    "STATUS_CODES",
    "VARIABLES",
    "INT_VARIABLES",
    "DOF_VARIABLES",
    "CONTACT_VARIABLES",
    "STATE_VARIABLE",
    "PAIR_VARIABLES",
    "LoopStatistics",
    "loop_statistics",
    "ChunkTask",
    "ChunkResult",
    "solve_chunk",
]

#: status name -> int8 code stored in the Dataset (``status`` variable): the steady-state statuses' own codes
STATUS_CODES = {s.value: s.code for s in SteadyStatus}
#: code of a point that was not computed (never written by a finished sweep), and its name
NOT_COMPUTED = -1
NOT_COMPUTED_NAME = "not-computed"

#: float result variables of a point, with units and meaning
VARIABLES = {
    "amplitude_q": ("1", "half peak-to-peak of q = kt x / fy (first contact's law) over one steady period"),
    "amplitude_m": ("m", "half peak-to-peak of x[response DOF] over one steady period"),
    "offset_m": ("m", "mean of x[response DOF] over one steady period (history dependent while sticking)"),
    "max_abs_m": ("m", "max |x[response DOF]| over one steady period"),
    "energy_contact_J": ("J", "energy dissipated by all contacts per forcing period"),
    "energy_viscous_J": ("J", "energy dissipated by viscous damping per forcing period"),
    "work_force_J": ("J", "work of the external forces per forcing period"),
}
#: integer result variables of a point
INT_VARIABLES = {
    "periods": ("1", "forcing periods integrated for this point"),
    "period_multiple": ("1", "the steady response repeats after this many forcing periods (0 if none)"),
    "not_settled_reason": ("1", "why a point is not-settled, a code: " + ", ".join(
        f"{i} {name}" for i, name in enumerate(config.SWEEP_NOT_SETTLED_REASONS)) + " (0 for the other points)"),
    "negative_dissipation": ("1", "1 where the periodic state's contact dissipation is negative beyond its "
                                  "energy-balance residual (a contact created energy: SteadyState.energy_check)"),
}
#: per requested DOF (dimension ``dof``), from the recorded steady period
DOF_VARIABLES = {
    "dof_amplitude_m": ("m", "half peak-to-peak of x[dof] over the steady period (cubic Hermite between samples)"),
    "dof_offset_m": ("m", "time mean of x[dof] over the steady period (cubic Hermite quadrature)"),
}
#: per contact (dimension ``contact``), from the recorded steady period
CONTACT_VARIABLES = {
    "contact_energy_J": ("J", "energy dissipated by the contact per forcing period (trapezoid of T du)"),
    "normal_mean_N": ("N", "time mean of the contact's normal force max(0, N)"),
    "normal_min_N": ("N", "smallest normal force max(0, N) over the recorded samples"),
    "normal_max_N": ("N", "largest normal force max(0, N) over the recorded samples"),
}
#: per interface node pair (dimension ``pair``, the pairs of all interfaces one after the other): the names of
#: the harmonic-balance branch's Dataset, with the SteadyState field each comes from
PAIR_VARIABLES = {
    "pair_energy_J": ("J", "energy dissipated by the node pair per forcing period", "pair_energy_J"),
    "pair_stick_fraction": ("1", "fraction of the steady period the pair is stuck", "pair_stick"),
    "pair_slip_fraction": ("1", "fraction of the steady period the pair is slipping", "pair_slip"),
    "pair_open_fraction": ("1", "fraction of the steady period the pair is open", "pair_open"),
}
#: per contact and motion state (dimensions ``contact``, ``state``)
STATE_VARIABLE = ("state_fraction", "1", "fraction of the steady period spent in each motion state "
                  "(to the step resolution)")


@dataclass(frozen=True)
class LoopStatistics:
    """Per-DOF and per-contact numbers of one recorded steady period.

    Attributes
    ----------
    dof_amplitude_m, dof_offset_m : ndarray (ndofs,)
        Half peak-to-peak and time mean of each requested DOF, m.
    contact_energy_J : ndarray (nc,)
        Energy dissipated per forcing period, J.
    normal_mean_N, normal_min_N, normal_max_N : ndarray (nc,)
        Time mean and extremes of the normal force max(0, N), N.
    state_fraction : ndarray (nc, len(STATE_NAMES))
        Fraction of the time in each motion state (``STATE_NAMES`` order).
    """

    dof_amplitude_m: np.ndarray
    dof_offset_m: np.ndarray
    contact_energy_J: np.ndarray
    normal_mean_N: np.ndarray
    normal_min_N: np.ndarray
    normal_max_N: np.ndarray
    state_fraction: np.ndarray


def _hermite(x0, x1, v0, v1, h, s):
    """Cubic Hermite interpolant at fractions s of steps of length h."""
    s2 = s * s
    s3 = s2 * s
    return (2 * s3 - 3 * s2 + 1) * x0 + (s3 - 2 * s2 + s) * h * v0 + (3 * s2 - 2 * s3) * x1 + (s3 - s2) * h * v1


def _dof_extrema(x, v, h):
    """(max, min) of the cubic Hermite interpolant of the samples x (velocities v).

    Inside a step whose end velocities have opposite signs the interpolant
    has one stationary point; both roots of its quadratic derivative are
    evaluated after clipping to the step, which adds only values the
    interpolant takes.
    """
    x0, x1, v0, v1 = x[:-1], x[1:], v[:-1], v[1:]
    m = v0 * v1 < 0.0
    hi, lo = float(np.max(x)), float(np.min(x))
    if not np.any(m):
        return hi, lo
    x0, x1, v0, v1, hm = x0[m], x1[m], v0[m], v1[m], h[m]
    d = (x1 - x0) / hm
    a = 3.0 * v0 + 3.0 * v1 - 6.0 * d
    b = -4.0 * v0 - 2.0 * v1 + 6.0 * d
    c = v0
    with np.errstate(divide="ignore", invalid="ignore"):
        q = -0.5 * (b + np.copysign(np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0)), b))
        roots = (np.nan_to_num(q / a), np.nan_to_num(c / q))
    for r in roots:
        val = _hermite(x0, x1, v0, v1, hm, np.clip(r, 0.0, 1.0))
        hi, lo = max(hi, float(val.max())), min(lo, float(val.min()))
    return hi, lo


def _selection_rows(system) -> np.ndarray:
    """Tangential selection B (nc, ndof): u_c = B[c] . x."""
    B = np.zeros((len(system.contacts), system.ndof))
    for i, c in enumerate(system.contacts):
        if c.direction is not None:
            B[i] = c.direction
        else:
            B[i, c.dof] += 1.0
            if c.dof2 >= 0:
                B[i, c.dof2] -= 1.0
    return B


def loop_statistics(loop, system, dofs, period_multiple: int = 1) -> LoopStatistics:
    """Per-DOF and per-contact numbers of a recorded steady period.

    Parameters
    ----------
    loop : Trajectory
        The final ``period_multiple`` forcing periods of a steady state
        (``steady_state(..., keep_loop=True).loop``), sampled at every step.
    system : System
        Its system.
    dofs : sequence of int
        DOFs whose amplitude and offset are wanted.
    period_multiple : int
        Forcing periods the loop spans (energies are per forcing period).

    Returns
    -------
    LoopStatistics
        Amplitudes and offsets from the cubic Hermite interpolant of the
        samples (as the solver's own amplitude); the energy of contact c as
        the trapezoid rule of the closed integral of T_c du_c (exact for a
        linear elastic contact, which dissipates nothing); normal forces
        max(0, N) (a tensile prescribed load means an open contact), time
        means by the trapezoid rule; state fractions by the state at the end
        of each step, weighted by its length.
    """
    t = np.asarray(loop.t, float)
    h = np.diff(t)
    span = t[-1] - t[0]
    amp, off = [], []
    for d in dofs:
        x, v = loop.x[:, d], loop.v[:, d]
        hi, lo = _dof_extrema(x, v, h)
        amp.append(0.5 * (hi - lo))
        off.append(float(np.sum(0.5 * h * (x[:-1] + x[1:]) + h * h * (v[:-1] - v[1:]) / 12.0)) / span)
    U = loop.x @ _selection_rows(system).T
    T = np.asarray(loop.T, float)
    energy = np.sum(0.5 * (T[:-1] + T[1:]) * np.diff(U, axis=0), axis=0) / max(int(period_multiple), 1)
    N = np.maximum(np.asarray(loop.N, float), 0.0)
    mean = np.sum(0.5 * (N[:-1] + N[1:]) * h[:, None], axis=0) / span
    codes = np.asarray(loop.code)[1:]
    frac = np.stack([np.sum(h[:, None] * (codes == s), axis=0) / span for s in range(len(STATE_NAMES))], axis=1)
    return LoopStatistics(np.array(amp), np.array(off), energy, mean, N.min(axis=0), N.max(axis=0), frac)


# --- chunks ---------------------------------------------------------------------------


@dataclass(frozen=True)
class ChunkTask:
    """Consecutive points of one line, in its sweep direction.

    Attributes
    ----------
    line : int
        Index of the line in the sweep.
    system_index : int
        Index of its System in the sweep's family.
    first : int
        Position of the first point along the line (0 = first in sweep order).
    gammas : tuple of float
        The chunk's gammas, in sweep order.
    start : Restart or None
        Warm start of the first point (None: the solver's linear estimate).
    rdof : int
        Response DOF of the System.
    dofs : tuple of int
        DOFs recorded per point (with ``loop_outputs``).
    ncontacts : int
        Width of the per-contact arrays.
    npairs : int
        Width of the per-pair arrays (0: none recorded).
    loop_outputs : bool
        Record per-DOF and per-contact outputs (keeps the steady loop).
    steps_per_period : int or None
        Integration steps per forcing period (None: solver default).
    steady : SteadyStateOptions or None
        The steady state's numbers (None: its defaults).
    where : str
        Prefix of a solver's refusal (ValueError), naming the System in its
        family (``"system 'a': "``); empty for a System swept alone.
    """

    line: int
    system_index: int
    first: int
    gammas: tuple
    start: object
    rdof: int
    dofs: tuple
    ncontacts: int
    loop_outputs: bool
    steps_per_period: int | None
    where: str = ""
    npairs: int = 0
    steady: object = None


@dataclass(frozen=True)
class ChunkResult:
    """The points a chunk finished.

    Attributes
    ----------
    line, first : int
        As in the task.
    done : int
        Points finished (the first ``done`` of the task; fewer than asked
        when the sweep was stopped).
    arrays : dict
        Per-point arrays of length ``done`` (sweep order): ``status`` and
        every result variable.
    restart : Restart or None
        Warm start of the point after the last finished one (None: cold).
    interrupted : bool
        True when an interrupt (KeyboardInterrupt) stopped the chunk.
    """

    line: int
    first: int
    done: int
    arrays: dict = field(repr=False)
    restart: object = field(repr=False)
    interrupted: bool = False


class Context:
    """What a running chunk shares with its sweep: a stop request and a
    count of finished points (process- or thread-shared objects, plain ones
    in the calling process, or on Dask a counter whose ``add(k)`` reports
    the points to the client)."""

    def __init__(self, stop=None, counter=None, on_point=None):
        self.stop = stop if stop is not None else threading.Event()
        self.counter = counter
        self.on_point = on_point

    def stopped(self) -> bool:
        """True once the sweep asked its chunks to stop."""
        return self.stop.is_set()

    def point_done(self) -> None:
        """Count one finished point."""
        add = getattr(self.counter, "add", None)  # a counter that reports elsewhere (Dask events)
        if add is not None:
            add(1)
        elif self.counter is not None:
            with self.counter.get_lock():
                self.counter.value += 1
        if self.on_point is not None:
            self.on_point()


def _steady_state_fn():
    """The time-domain steady-state solver (resolved late; tests may swap it: the one place they do)."""
    from ..dynamics import steady_state

    return steady_state


def _solver():
    """The steady-state solver: :func:`_steady_state_fn`, looked up at every chunk."""
    return _steady_state_fn()


def empty_arrays(m: int, ndofs: int, nc: int, loop_outputs: bool, npairs: int = 0) -> dict:
    """Result arrays of ``m`` points, not computed (NaN, 0, status NOT_COMPUTED); per-pair arrays
    (:data:`PAIR_VARIABLES`) when ``npairs`` > 0."""
    out = {name: np.full(m, np.nan) for name in VARIABLES}
    if npairs:
        out.update({name: np.full((m, npairs), np.nan) for name in PAIR_VARIABLES})
    out.update({name: np.zeros(m, dtype=np.int32) for name in INT_VARIABLES})
    out["status"] = np.full(m, NOT_COMPUTED, dtype=np.int8)
    if loop_outputs:
        out.update({name: np.full((m, ndofs), np.nan) for name in DOF_VARIABLES})
        out.update({name: np.full((m, nc), np.nan) for name in CONTACT_VARIABLES})
        out[STATE_VARIABLE[0]] = np.full((m, nc, len(STATE_NAMES)), np.nan)
    return out


def not_settled_reason(res) -> int:
    """Code (``config.SWEEP_NOT_SETTLED_REASONS``) of why the steady state
    ``res`` is not-settled, from its ``message``; 0 when it is not."""
    if res.status != "not-settled":
        return 0
    message = str(getattr(res, "message", ""))
    name = "long-period" if message.startswith("period-") else message
    reasons = config.SWEEP_NOT_SETTLED_REASONS
    return reasons.index(name) if name in reasons else 0


def _store(out: dict, k: int, res, system, task: ChunkTask) -> None:
    """Point k of the chunk from the steady state ``res``."""
    if res.status not in STATUS_CODES:
        raise RuntimeError(f"steady_state returned unknown status {res.status!r}")
    out["status"][k] = STATUS_CODES[res.status]
    for name in VARIABLES:
        out[name][k] = float(getattr(res, name, math.nan))
    out["periods"][k] = int(res.periods)
    out["period_multiple"][k] = int(getattr(res, "period_multiple", 0) or 0)
    out["not_settled_reason"][k] = not_settled_reason(res)
    out["negative_dissipation"][k] = int(getattr(res, "energy_check", None) == EnergyCheck.NEGATIVE_DISSIPATION)
    if task.npairs:
        for name, (_, _, field_name) in PAIR_VARIABLES.items():
            val = np.asarray(getattr(res, field_name, ()), dtype=np.float64)
            out[name][k, : val.shape[0]] = val
    loop = getattr(res, "loop", None)
    if task.loop_outputs and loop is not None:
        st = loop_statistics(loop, system, task.dofs, out["period_multiple"][k])
        for name in (*DOF_VARIABLES, *CONTACT_VARIABLES, STATE_VARIABLE[0]):
            val = getattr(st, name)
            out[name][k, : val.shape[0]] = val


def solve_chunk(task: ChunkTask, system, ctx: Context | None = None) -> ChunkResult:
    """Solve the points of ``task`` in order, each warm-started from the previous.

    Stops early (returning the points finished) when ``ctx`` asks to stop or
    on KeyboardInterrupt (the point in progress is dropped).
    """
    solve = _solver()
    m = len(task.gammas)
    out = empty_arrays(m, len(task.dofs), task.ncontacts, task.loop_outputs, task.npairs)
    kwargs = {"keep_loop": bool(task.loop_outputs), "response_dof": task.rdof}
    if task.steps_per_period is not None:
        kwargs["steps_per_period"] = task.steps_per_period
    if task.steady is not None:
        kwargs["options"] = task.steady
    start, done, interrupted = task.start, 0, False
    try:
        for k, g in enumerate(task.gammas):
            if ctx is not None and ctx.stopped():
                break
            res = solve(system, float(g), start=start, **kwargs)
            _store(out, k, res, system, task)
            start = None if res.status == "unbounded" else res.restart
            done = k + 1
            if ctx is not None:
                ctx.point_done()
    except KeyboardInterrupt:
        interrupted = True
    except ValueError as exc:
        if not task.where:
            raise
        raise ValueError(f"{task.where}{exc}") from None
    arrays = {name: a[:done] for name, a in out.items()}
    return ChunkResult(line=task.line, first=task.first, done=done, arrays=arrays, restart=start,
                       interrupted=interrupted)
