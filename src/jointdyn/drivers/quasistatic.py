"""Quasi-static hysteresis: march a contact law over a prescribed history.

The tangential displacement x(t) and the normal load N(t) are prescribed
(docs/model.md sections 1 and 6, paper section 2.2, Figs 2-4); inertia plays no
part, so the force is the law's response to the history and time only
orders the samples. This module builds the paper's harmonic history, reads
a history from CSV, marches any registered law over it and reduces the
result to per-cycle loop metrics (dissipated energy, force extremes, time
spent in each motion state, secant stiffness, equivalent loss factor).

Separation is never smeared over a step: the instants where N crosses zero
are samples of the history (exact for the harmonic shorthand, by linear
interpolation for sampled input), N is exactly 0 there, and contact restarts
at exactly the re-contact displacement (see :func:`quasistatic`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

#: a cycle of a sampled history spans at least this many sample intervals on
#: average (fewer is not a sampled loop); bounds the cycles of --period
QS_MIN_INTERVALS_PER_CYCLE = 2
#: load (as a fraction of n_ref) at which a law is evaluated at a re-contact
#: instant (N = 0 followed by N > 0), so that the virgin curve starts exactly
#: there; the sample is reported as separated with T = 0
QS_RECONTACT_LOAD = 1e-300

if TYPE_CHECKING:
    import pandas as pd

from .. import _validate as V
from .. import config
from ..kinematics import HarmonicLoad, NormalSpring
from ..laws import MACROSLIP, SEPARATION, STATE_NAMES, STICK_SLIP, ContactLaw
from ..status import Status
from ._csv import read_history_csv
from ._march import march

__all__ = [
    "LoopResult",
    "LoopStatus",
    "harmonic_history",
    "read_history_csv",
    "quasistatic",
    "harmonic_loop",
    "cycle_count",
    "CYCLE_COLUMNS",
]

#: columns of :attr:`LoopResult.cycles`, in order
CYCLE_COLUMNS = (
    "cycle",
    "t_start_s",
    "t_end_s",
    "energy_J",
    "force_max_N",
    "force_min_N",
    "x_max_m",
    "x_min_m",
    "stick_slip_fraction",
    "macroslip_fraction",
    "separation_fraction",
    "secant_stiffness_N_per_m",
    "loss_factor",
    "energy_per_cycle_J",  # deprecated duplicate of energy_J, kept for one release (CHANGELOG)
)


# --------------------------------------------------------------------------
# histories
# --------------------------------------------------------------------------
def harmonic_history(
    amplitude,
    frequency,
    n0,
    eta=0.0,
    delta_deg=0.0,
    cycles=config.QS_CYCLES,
    steps_per_cycle=config.QS_STEPS_PER_CYCLE,
    x_offset=0.0,
    kn=None,
):
    """The paper's quasi-static history (paper section 2.2, docs/model.md section 6).

    ``x(t) = x_offset + A sin(2 pi f t)`` and
    ``N(t) = N0 + eta N0 sin(2 pi f t + delta)`` on ``0 <= t <= cycles / f``,
    sampled uniformly with ``steps_per_cycle`` steps per period, plus the exact
    separation and re-contact instants (:meth:`HarmonicLoad.zero_crossings`),
    where N is set to exactly 0. Separation therefore starts and ends on a
    sample, never inside a step.

    Parameters
    ----------
    amplitude : float
        Tangential displacement amplitude A, m (> 0).
    frequency : float
        Frequency f, Hz (> 0); the period is 1 / f.
    n0 : float
        Static normal load N0, N (> 0).
    eta : float
        Normal-load ratio N1 / N0 (>= 0); the interface separates during part
        of the cycle iff eta > 1.
    delta_deg : float
        Phase delta of the normal load relative to x, degrees (finite).
    cycles : int
        Number of periods (>= 1).
    steps_per_cycle : int
        Uniform steps per period (>= 4); ``cycles x steps_per_cycle`` is at
        most :data:`config.QS_MAX_SAMPLES`.
    x_offset : float
        Constant added to x, m (finite).
    kn : float, optional
        Normal stiffness, N/m (> 0). If given, N comes from the unilateral
        spring ``N = max(0, N0 + kn v)`` (docs/model.md section 1) driven by the
        prescribed normal motion ``v = (eta N0 / kn) sin(2 pi f t + delta)``,
        m. This equals the prescribed load while in contact and 0 (instead
        of negative) while separated, so the tangential response does not
        depend on kn; only the reported N does.

    Returns
    -------
    t, x, N : ndarray
        Times (s, strictly increasing), displacement (m), normal load (N).

    Raises
    ------
    ValueError
        An input out of range (the message names it).
    """
    A = V.positive("amplitude", amplitude)
    f = V.positive("frequency", frequency)
    n0 = V.positive("n0", n0)
    eta = V.nonnegative("eta", eta)
    delta_deg = V.finite("delta_deg", delta_deg)
    cycles = V.positive_int("cycles", cycles, 1)
    steps = V.positive_int("steps_per_cycle", steps_per_cycle, 4)
    x_offset = V.finite("x_offset", x_offset)
    if kn is not None:
        kn = V.positive("kn", kn)
    V.count_at_most("cycles x steps_per_cycle", float(cycles) * steps, config.QS_MAX_SAMPLES, "samples")
    V.derived("cycles / frequency (duration, s)", cycles / f)
    V.derived("eta x n0 (normal-load amplitude, N)", eta * n0)
    V.derived("|x_offset| + amplitude (largest displacement, m)", abs(x_offset) + A)
    w = 2.0 * math.pi * f
    # t_i = (i / steps) / f: the period boundaries k / f are exact samples
    t = (np.arange(cycles * steps + 1) / steps) / f
    t_end = t[-1]
    load = HarmonicLoad(n0=n0, n1=eta * n0, phase_deg=delta_deg)
    tc = load.zero_crossings(w, 0.0, t_end)
    dt = 1.0 / (steps * f)
    snap = config.QS_SNAP_RTOL * dt
    crossing = np.zeros(t.size, dtype=bool)
    extra = []
    for c in tc:
        i = int(np.clip(np.searchsorted(t, c), 1, t.size - 1))
        j = i if abs(t[i] - c) <= abs(t[i - 1] - c) else i - 1
        if abs(t[j] - c) <= snap:
            t[j] = c
            crossing[j] = True
        else:
            extra.append(c)
    if extra:
        t = np.concatenate((t, extra))
        crossing = np.concatenate((crossing, np.ones(len(extra), dtype=bool)))
        order = np.argsort(t, kind="stable")
        t = t[order]
        crossing = crossing[order]
    phase = w * t
    x = x_offset + A * np.sin(phase)
    if kn is None:
        N = load.at(phase)
    else:
        v = (eta * n0 / kn) * np.sin(phase + load.phase_rad)
        N = NormalSpring(kn=kn, preload=n0).load(v)
    N[crossing] = 0.0
    return t, x, N


# --------------------------------------------------------------------------
# result
# --------------------------------------------------------------------------
class LoopStatus(Status):
    """Outcome of a quasi-static march (:attr:`LoopResult.status`).

    Bad input raises ``ValueError`` before marching and the march itself
    cannot fail, so a result is always ``ok``; the status is there so that a
    loop says what it is as every other result does (``status.ok``,
    ``message``).
    """

    OK = "ok", "the law was marched over the whole history", True


@dataclass(frozen=True, eq=False)
class LoopResult:
    """Response of a contact law to a prescribed history, with loop metrics.

    Attributes
    ----------
    t, x, N : ndarray
        The history actually marched: times (s), tangential displacement (m),
        normal load (N); includes any inserted zero-crossing instants.
    T : ndarray
        Tangential contact force, N (exactly 0 wherever N <= 0).
    kT : ndarray
        Tangent stiffness dT/dx at fixed N, N/m.
    code : ndarray of int8
        Motion state per sample: STICK_SLIP (0), MACROSLIP (1), SEPARATION
        (2); a sample with N <= 0 is SEPARATION.
    period : float or None
        Cycle length, s; None when the whole history is one window.
    cycles : pandas.DataFrame
        One row per full cycle (columns :data:`CYCLE_COLUMNS`; see
        :func:`quasistatic` for the definitions).
    law_name : str
        The law's registry name.
    status : LoopStatus
        ``"ok"`` (bad input raises ValueError before marching; the march
        itself cannot fail); ``message`` says what it means.
    n_inserted : int
        Number of zero-crossing instants of N inserted into the input history.
    inserted : ndarray of bool
        True for the samples that are not samples of the input history (the
        inserted zero-crossing instants); ``n_inserted`` of them.
    """

    t: np.ndarray
    x: np.ndarray
    N: np.ndarray
    T: np.ndarray
    kT: np.ndarray
    code: np.ndarray
    period: float | None
    cycles: pd.DataFrame
    law_name: str
    status: LoopStatus = LoopStatus.OK
    n_inserted: int = 0
    inserted: np.ndarray | None = None

    @property
    def message(self) -> str:
        """What the status means, in one line."""
        return self.status.message

    @property
    def n_cycles(self) -> int:
        """Number of full cycles analysed."""
        return len(self.cycles)

    @property
    def state(self) -> np.ndarray:
        """Motion-state names per sample (``stick-slip``, ``macroslip``, ``separation``)."""
        return np.asarray(STATE_NAMES, dtype=object)[self.code.astype(np.intp)]

    def cycle_slice(self, k: int = -1) -> slice:
        """Index slice of the samples of cycle ``k`` (both ends included).

        Cycle boundaries that fall between samples are not samples of the
        marched history; then the slice covers the samples inside the cycle.
        """
        k = int(k)
        if k < 0:
            k += self.n_cycles
        if not 0 <= k < self.n_cycles:
            raise ValueError(f"cycle must be in [0, {self.n_cycles - 1}], got {k}")
        row = self.cycles.iloc[k]
        tol = config.QS_SNAP_RTOL * (self.t[-1] - self.t[0])
        i0 = int(np.searchsorted(self.t, row["t_start_s"] - tol, side="left"))
        i1 = int(np.searchsorted(self.t, row["t_end_s"] + tol, side="right"))
        return slice(i0, i1)

    def last_cycle(self) -> dict:
        """Metrics of the last full cycle as a plain dict (JSON-friendly floats)."""
        row = self.cycles.iloc[-1]
        out = {}
        for c in CYCLE_COLUMNS:
            v = row[c]
            out[c] = int(v) if c == "cycle" else float(v)
        return out


# --------------------------------------------------------------------------
# driver
# --------------------------------------------------------------------------
def _insert_crossings(t, x, N):
    """Insert the instants where N changes sign strictly between samples.

    x and N are taken linear between samples; N is exactly 0 at the new
    samples. A crossing instant that rounds onto a neighbouring sample time
    is not inserted, so every input sample stays.

    Returns
    -------
    t, x, N : ndarray
        The history with the crossing instants.
    inserted : ndarray of bool
        True at the inserted samples.
    """
    pos = N > 0.0
    neg = N < 0.0
    i = np.flatnonzero((pos[:-1] & neg[1:]) | (neg[:-1] & pos[1:]))
    if i.size == 0:
        return t, x, N, np.zeros(t.size, dtype=bool)
    r = N[i] / (N[i] - N[i + 1])  # in (0, 1)
    tc = t[i] + r * (t[i + 1] - t[i])
    xc = x[i] + r * (x[i + 1] - x[i])
    inside = (tc > t[i]) & (tc < t[i + 1])
    i, tc, xc = i[inside], tc[inside], xc[inside]
    inserted = np.insert(np.zeros(t.size, dtype=bool), i + 1, True)
    return np.insert(t, i + 1, tc), np.insert(x, i + 1, xc), np.insert(N, i + 1, 0.0), inserted


def _interval_states(N, code):
    """Per-interval time fractions of separation and the contact state.

    Returns ``sep`` (fraction of each interval with N <= 0, exact for N linear
    between samples) and ``contact`` (STICK_SLIP or MACROSLIP for the rest of
    the interval: the state the law reports at the interval's end, or at its
    start when the end is separated; stick-slip when contact starts inside).
    """
    a, b = N[:-1], N[1:]
    sep = np.where((a <= 0.0) & (b <= 0.0), 1.0, 0.0)
    mixed = (a > 0.0) != (b > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # fraction of a linear segment on which N <= 0
        frac = np.where(a > 0.0, b / (b - a), a / (a - b))
    sep = np.where(mixed, np.clip(frac, 0.0, 1.0), sep)
    c0, c1 = code[:-1], code[1:]
    contact = np.where(c1 != SEPARATION, c1, np.where(c0 != SEPARATION, c0, STICK_SLIP))
    return sep, contact


def _refine(t, x, N, T, code, bounds):
    """Insert the cycle boundaries as samples (all quantities linear in t)."""
    tol = config.QS_SNAP_RTOL * (t[-1] - t[0])
    new_t = []
    for b in bounds:
        j = int(np.searchsorted(t, b))
        near = [k for k in (j - 1, j) if 0 <= k < t.size and abs(t[k] - b) <= tol]
        if not near:
            new_t.append(b)
    if not new_t:
        return t, x, N, T, code, np.zeros(t.size, dtype=bool)
    new_t = np.asarray(new_t)
    j = np.searchsorted(t, new_t)
    r = (new_t - t[j - 1]) / (t[j] - t[j - 1])

    def lin(a):
        return a[j - 1] + r * (a[j] - a[j - 1])

    ins_code = np.where(code[j] != SEPARATION, code[j], code[j - 1]).astype(code.dtype)
    added = np.zeros(t.size + new_t.size, dtype=bool)
    added[j + np.arange(new_t.size)] = True
    return (
        np.insert(t, j, new_t),
        np.insert(x, j, lin(x)),
        np.insert(N, j, lin(N)),
        np.insert(T, j, lin(T)),
        np.insert(code, j, ins_code),
        added,
    )


def _window_metrics(t, x, T, sep, contact, i0, i1):
    """Loop metrics over samples i0..i1 (inclusive)."""
    tt = t[i0 : i1 + 1]
    xx = x[i0 : i1 + 1]
    TT = T[i0 : i1 + 1]
    dt = np.diff(tt)
    s = sep[i0:i1]
    cc = contact[i0:i1]
    total = tt[-1] - tt[0]
    f_sep = float(np.sum(dt * s) / total)
    f_macro = float(np.sum(dt * (1.0 - s) * (cc == MACROSLIP)) / total)
    f_stick = float(np.sum(dt * (1.0 - s) * (cc == STICK_SLIP)) / total)
    # trapezoidal integral of T dx along the path (closed cycle: loop area)
    energy = float(np.sum(0.5 * (TT[1:] + TT[:-1]) * np.diff(xx)))
    imax = int(np.argmax(xx))
    imin = int(np.argmin(xx))
    span = xx[imax] - xx[imin]
    if span > 0.0:
        ksec = float((TT[imax] - TT[imin]) / span)
    else:
        ksec = math.nan
    X = 0.5 * span
    U = 0.5 * ksec * X * X
    loss = energy / (2.0 * math.pi * U) if (U > 0.0 and math.isfinite(U)) else math.nan
    return {
        "t_start_s": float(tt[0]),
        "t_end_s": float(tt[-1]),
        "energy_J": energy,
        "force_max_N": float(np.max(TT)),
        "force_min_N": float(np.min(TT)),
        "x_max_m": float(xx[imax]),
        "x_min_m": float(xx[imin]),
        "stick_slip_fraction": f_stick,
        "macroslip_fraction": f_macro,
        "separation_fraction": f_sep,
        "secant_stiffness_N_per_m": ksec,
        "loss_factor": loss,
        "energy_per_cycle_J": energy,
    }


def cycle_count(t, period, name: str = "period") -> int:
    """Number of full cycles of length ``period`` in the history sampled at ``t``.

    Bounded before anything is computed: at least one cycle, and at most one
    per :data:`QS_MIN_INTERVALS_PER_CYCLE` sample intervals (a cycle
    has to be sampled to be a loop; this also bounds the work by the size of
    the history, whatever ``period``).

    Parameters
    ----------
    t : ndarray
        Sample times, s (finite, strictly increasing, >= 2 samples).
    period : float
        Cycle length, s (> 0).
    name : str
        How error messages name ``period`` (the CLI passes ``--period``).

    Returns
    -------
    int
        The number of full cycles, >= 1.

    Raises
    ------
    ValueError
        ``period`` out of range; the message gives the allowed range.
    """
    period = V.positive(name, period)
    duration = float(t[-1] - t[0])
    most = max(1, (len(t) - 1) // QS_MIN_INTERVALS_PER_CYCLE)
    ratio = duration / period * (1.0 + config.QS_SNAP_RTOL)  # inf for a tiny period: compared as a float
    if not ratio < most + 1:
        raise ValueError(
            f"{name} must be at least {duration / most!r} s (at most {most} cycle{'s' if most > 1 else ''} of "
            f">= {QS_MIN_INTERVALS_PER_CYCLE} sample intervals in {len(t)} samples over {duration!r} s), "
            f"got {period!r}"
        )
    if ratio < 1.0:
        raise ValueError(f"{name} must be at most the duration of the history ({duration!r} s), got {period!r}")
    return int(math.floor(ratio))


def quasistatic(law, t, x, N, *, period=None, state=None) -> LoopResult:
    """March ``law`` over a prescribed history and measure its loops.

    The law (any registered law: the exact Iwan law, docs/model.md section 5 at
    n -> infinity; the closed forms, paper section 2.1 / docs/model.md section 3;
    discrete Iwan, docs/model.md section 5; Jenkins) is stepped sample by sample
    from its virgin state at ``x[0], N[0]`` (or ``state``).

    Separation (docs/model.md section 4): wherever N changes sign strictly
    between two samples, the crossing instant (x and N linear in t) is
    inserted as a sample with N = 0. A sample with N exactly 0 followed by a
    positive load is the re-contact instant: the law is evaluated there with
    a vanishing positive load (``1e-300 * n_ref``) so that its virgin curve
    starts at exactly that displacement (docs/model.md section 3, "virgin state");
    the sample is reported as separated, with T = 0. Every sample with
    N <= 0 is SEPARATION with T = 0.

    Cycles: with ``period`` P, cycle k is the window
    ``[t[0] + k P, t[0] + (k + 1) P]`` for every full window in the history
    (window ends that fall between samples are interpolated linearly for
    the metrics); without ``period`` the whole history is one window, and
    its "energy" is the work done by T along the path (equal to the loop
    area only if the path is a closed loop).

    Per-cycle metrics (columns of :attr:`LoopResult.cycles`):

    - ``energy_J``: trapezoidal integral of T dx over the window (a row is one
      cycle; ``energy_per_cycle_J``, the last column, is its deprecated duplicate),
      J. For a closed steady cycle this is the loop area, the energy
      dissipated per cycle (docs/model.md section 2: kt^2 A^3 / (3 fy) for
      A <= 2 fy / kt, 4 fy A - 16 fy^2 / (3 kt) beyond, at constant N).
    - ``force_max_N`` / ``force_min_N``: extremes of T, N.
    - ``x_max_m`` / ``x_min_m``: extremes of x, m.
    - ``stick_slip_fraction``, ``macroslip_fraction``,
      ``separation_fraction``: fractions of the window's duration in each
      motion state (they sum to 1). Separation is timed exactly for N linear
      between samples; the contact part of each step is given the state the
      law reports at the end of the step.
    - ``secant_stiffness_N_per_m``: k_sec = (T(x_max) - T(x_min)) /
      (x_max - x_min), N/m, T taken at the samples where x is extreme.
    - ``loss_factor``: equivalent loss factor E / (2 pi U) with the
      secant strain energy U = k_sec X^2 / 2, X = (x_max - x_min) / 2 (NaN
      when k_sec <= 0 or x does not move).

    Parameters
    ----------
    law : ContactLaw
        Any registered law (:func:`jointdyn.make_law`).
    t : array_like
        Times, s (finite, strictly increasing, at least 2 samples).
    x : array_like
        Tangential displacement, m (finite, same length).
    N : array_like
        Normal load, N (finite, same length; N <= 0 is separation).
    period : float, optional
        Cycle length, s (> 0, at most the duration of the history, and long
        enough for :data:`QS_MIN_INTERVALS_PER_CYCLE` sample
        intervals per cycle on average; see :func:`cycle_count`).
    state : ndarray, optional
        Committed law state to start from (default: virgin at x[0], N[0]).

    Returns
    -------
    LoopResult
        Sampled response and per-cycle metrics.

    Raises
    ------
    ValueError
        Bad input (message names the parameter): arrays of different
        lengths, NaN/inf, t not strictly increasing, bad period.
    """
    if not isinstance(law, ContactLaw):
        raise ValueError(f"law must be a ContactLaw (see jointdyn.make_law), got {type(law).__name__}")
    t = V.finite_array("t", t)
    x = V.finite_array("x", x)
    N = V.finite_array("N", N)
    V.same_length(t=t, x=x, N=N)
    if t.size < 2:
        raise ValueError(f"t must have at least 2 samples, got {t.size}")
    V.increasing("t", t)
    if period is not None:
        period = V.positive("period", period)
        ncyc = cycle_count(t, period)
    t, x, N, inserted = _insert_crossings(t, x, N)

    # re-contact instants: N == 0 followed by N > 0
    recontact = np.zeros(N.size, dtype=bool)
    recontact[:-1] = (N[:-1] == 0.0) & (N[1:] > 0.0)
    Nk = N.copy()
    Nk[recontact] = QS_RECONTACT_LOAD * law.n_ref
    T, kT, code, _ = march(law, x, Nk, state=state)
    open_ = N <= 0.0
    T[open_] = 0.0
    kT[open_] = 0.0
    code[open_] = SEPARATION

    if period is None:
        bounds = [float(t[0]), float(t[-1])]
    else:
        bounds = [float(t[0]) + k * period for k in range(ncyc + 1)]
        bounds[-1] = min(bounds[-1], float(t[-1]))
    tr, xr, Nr, Tr, cr, _ = _refine(t, x, N, T, code, bounds)
    sep, contact = _interval_states(Nr, cr)
    tol = config.QS_SNAP_RTOL * (tr[-1] - tr[0])
    rows = []
    for k in range(len(bounds) - 1):
        i0 = int(np.searchsorted(tr, bounds[k] - tol))
        i1 = int(np.searchsorted(tr, bounds[k + 1] + tol, side="right")) - 1
        m = _window_metrics(tr, xr, Tr, sep, contact, i0, i1)
        m["cycle"] = k
        rows.append(m)
    import pandas as pd  # here: the package's other commands start faster without it

    cycles = pd.DataFrame(rows, columns=list(CYCLE_COLUMNS))
    return LoopResult(
        t=t,
        x=x,
        N=N,
        T=T,
        kT=kT,
        code=code,
        period=period,
        cycles=cycles,
        law_name=getattr(law, "name", type(law).__name__),
        status=LoopStatus.OK,
        n_inserted=int(np.count_nonzero(inserted)),
        inserted=inserted,
    )


def harmonic_loop(
    law,
    amplitude,
    frequency=1.0,
    n0=None,
    eta=0.0,
    delta_deg=0.0,
    cycles=config.QS_CYCLES,
    steps_per_cycle=config.QS_STEPS_PER_CYCLE,
    x_offset=0.0,
    kn=None,
) -> LoopResult:
    """:func:`quasistatic` over :func:`harmonic_history`, period 1 / frequency.

    ``n0`` defaults to the law's ``n_ref`` (the paper's N_ref = N0); the other
    parameters are those of :func:`harmonic_history` (``delta_deg`` in degrees).
    """
    if not isinstance(law, ContactLaw):
        raise ValueError(f"law must be a ContactLaw (see jointdyn.make_law), got {type(law).__name__}")
    n0 = law.n_ref if n0 is None else n0
    t, x, N = harmonic_history(amplitude, frequency, n0, eta, delta_deg, cycles, steps_per_cycle, x_offset, kn)
    return quasistatic(law, t, x, N, period=1.0 / float(frequency))
