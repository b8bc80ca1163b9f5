"""Steady periodic response of a harmonically forced System, with classification.

:func:`steady_state` integrates (RK4 core, ``_core.py``) until the response
repeats with the forcing period, or with a multiple p <= 4 of it, within
tolerances on the half peak-to-peak amplitude, the period-boundary state
(Poincare points) and the energy per period over K windows; otherwise it
classifies the run as ``"unbounded"`` (amplitude still growing, e.g. the Den
Hartog case of docs/model.md section 6) or ``"not-settled"``. When the transient
decays slowly (lightly damped cases, docs/model.md section 7) it computes the
periodic state directly by shooting: Newton on the period map of (x, v) with
the law state carried along, finite-difference monodromy matrix, minimum-norm
(least-squares) steps because the offset of a partly stuck contact is
neutral (a multiplier 1).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V
from .._jit import jit
from ..systems import System
from ._core import N_SUMMARY, S_EC, S_EV, S_STEPS, S_W, S_XMAX, S_XMEAN, S_XMIN
from ._model import Model, make_model, pack_system, refine_if_opened
from ._start import clean_states, free_body_start, linear_start
from .integrate import Restart, Trajectory, _omega, _trajectory
from .monodromy import fd_monodromy
from .options import SteadyStateOptions, march_with_steps, steady_options
from .status import SS_DISSIPATION_FLOOR, EnergyCheck, SteadyStatus

__all__ = ["SteadyState", "energy_check", "prepare_kernels", "steady_state"]

@dataclass(frozen=True)
class SteadyState:
    """Result of :func:`steady_state`.

    Every amplitude/energy field is NaN unless ``status == "periodic"``: a
    run that did not settle is never reported as a plain number (the last
    observed amplitude is kept in ``last_amplitude_m`` for diagnostics).

    Attributes
    ----------
    status : SteadyStatus
        ``"periodic"``, ``"not-settled"`` or ``"unbounded"`` (its ``message``
        says what it means).
    message : str
        More on the status: ``"integration"`` or ``"shooting"`` (how a
        periodic state was reached); ``"growing"``, ``"blow-up"``
        (unbounded); ``"period-P"`` (repeats every P > ``SteadyStateOptions.max_multiple``
        periods), ``"slowly-converging"`` (Poincare distance still
        shrinking at max_periods), ``"quasi-periodic-or-chaotic"`` (the
        one-period mismatch stopped shrinking over ``SteadyStateOptions.stall_periods`` periods,
        after shooting; quasi-periodic and chaotic are not told apart).
    period_multiple : int
        p: the response repeats every p forcing periods (0 if not periodic).
    gamma, omega : float
        Frequency ratio w / w0 and excitation frequency w (rad/s).
    amplitude_q : float
        kt X / fy of the first contact's law (docs/model.md section 6).
    amplitude_m : float
        X = half peak-to-peak of x[response_dof] over the final p periods, m.
    offset_m : float
        Time mean of x[response_dof] over the final p periods, m.
    max_abs_m : float
        max |x[response_dof]| over the final p periods, m.
    energy_contact_J, energy_viscous_J, work_force_J : float
        Energy dissipated by all contacts, by viscous damping, and work of
        the forcing, per forcing period (J), averaged over the final p periods.
    periods : int
        Forcing periods integrated (shooting evaluations included).
    steps : int
        RK4 steps taken (all periods).
    shooting_iterations : int
        Newton iterations spent in shooting (0 if not used).
    floquet_max : float
        Largest |Floquet multiplier| from the last shooting Jacobian (NaN if none).
    energy_check : EnergyCheck
        ``"passive"``, ``"negative-dissipation"`` (the contact created energy
        over the period beyond the energy-balance residual; a
        ``RuntimeWarning`` is issued too) or ``"not-checked"`` (not
        periodic); see :func:`energy_check`.
    last_amplitude_m : float
        Half peak-to-peak of the last integrated period, m (diagnostic; not a result).
    restart : Restart
        x, v and law states at the final period boundary (warm start).
    loop : Trajectory or None
        The final p periods, sampled at every step (if ``keep_loop``).
    pair_energy_J : ndarray (npairs,)
        Per interface pair (the pairs of ``system.interfaces`` one after
        the other), the energy it dissipates per forcing period (J, the work
        of its tangential force over the final p periods, averaged); NaN
        unless periodic. Their sum is part of ``energy_contact_J``.
    pair_stick, pair_slip, pair_open : ndarray (npairs,)
        Fractions of the period each pair is stuck, slipping, open (they
        add up to 1; openings and closings are step boundaries, a change
        between stick and slip inside a step counts half a step to each);
        NaN unless periodic.
    """

    status: SteadyStatus
    message: str
    period_multiple: int
    gamma: float
    omega: float
    amplitude_q: float
    amplitude_m: float
    offset_m: float
    max_abs_m: float
    energy_contact_J: float
    energy_viscous_J: float
    work_force_J: float
    periods: int
    steps: int
    shooting_iterations: int
    floquet_max: float
    energy_check: EnergyCheck
    last_amplitude_m: float
    restart: Restart = field(repr=False)
    loop: Trajectory | None = field(default=None, repr=False)
    pair_energy_J: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    pair_stick: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    pair_slip: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    pair_open: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)

    def to_record(self) -> dict:
        """The scalar fields as a flat dict (one row of a sweep table)."""
        keys = (
            "status", "message", "period_multiple", "gamma", "omega", "amplitude_q", "amplitude_m",
            "offset_m", "max_abs_m", "energy_contact_J", "energy_viscous_J", "work_force_J",
            "periods", "steps", "shooting_iterations", "floquet_max", "energy_check", "last_amplitude_m",
        )  # fmt: skip
        return {k: getattr(self, k) for k in keys}


class _History:
    """Per-period summaries since the last jump of the state.

    ``summ`` (periods x N_SUMMARY) and ``Z`` (periods + 1 x 2n, the state at
    the period boundaries) are arrays, so the periodicity checks slice views.
    """

    def __init__(self, z0):
        z0 = np.array(z0, dtype=float)
        self.Z = z0[None, :]
        self.summ = np.empty((0, N_SUMMARY))
        self.pairs = []  # per-period (npairs, 4) summaries of the interface pairs
        self.shot_checked = False

    def add(self, summ, zend, pairs=None):
        self.summ = np.concatenate([self.summ, summ])
        self.Z = np.concatenate([self.Z, zend])
        if pairs is not None:
            self.pairs.extend(pairs)

    @property
    def size(self):
        return len(self.summ)


def _amplitude_scale(model, A):
    floor = 1e-14 + 1e-9 * model.pack.xlin
    return max(A, floor)


@jit
def _periodic_arrays(summ, Z, p, K, n, w, K_stuck, M, floor, amp_rtol, energy_rtol, balance_rtol):  # pragma: no cover - compiled
    """:func:`_check_periodic` on the history arrays (compiled: it runs for
    every candidate multiple p after every chunk of periods)."""
    P = summ.shape[0]
    m = K * p
    if P < m:
        return False
    r0 = P - m
    amax = -np.inf
    amin = np.inf
    emax = -np.inf
    emin = np.inf
    wmax = -np.inf
    wmin = np.inf
    esum = 0.0
    wsum = 0.0
    flow = 0.0
    for k in range(K):
        hi = -np.inf
        lo = np.inf
        e = 0.0
        wk = 0.0
        for j in range(p):
            row = r0 + k * p + j
            hi = max(hi, summ[row, S_XMAX])
            lo = min(lo, summ[row, S_XMIN])
            e += summ[row, S_EC] + summ[row, S_EV]
            wk += summ[row, S_W]
        amp = 0.5 * (hi - lo)
        e /= p
        wk /= p
        amax = max(amax, amp)
        amin = min(amin, amp)
        emax = max(emax, e)
        emin = min(emin, e)
        wmax = max(wmax, wk)
        wmin = min(wmin, wk)
        esum += e
        wsum += wk
        flow = max(flow, abs(e), abs(wk))
    A = amax
    xs = max(A, floor)
    if A - amin > amp_rtol * xs:
        return False
    # Poincare points one window apart
    wscale = max(w, 1e-300)
    for k in range(K):
        a = r0 + k * p
        b = a + p
        for i in range(n):
            if abs(Z[b, i] - Z[a, i]) > amp_rtol * xs:
                return False
            if abs(Z[b, n + i] - Z[a, n + i]) > amp_rtol * xs * wscale:
                return False
    # energy scale: the flow per period, but not below amp_rtol times the
    # energy stored in the motion (a residual transient of relative size
    # amp_rtol exchanges that much per period; matters when almost nothing
    # is dissipated, e.g. beta = 1000 far from resonance)
    zl = Z.shape[0] - 1
    stored = 0.0
    kdiag = 0.0
    for i in range(n):
        kdiag = max(kdiag, K_stuck[i, i])
        for j in range(n):
            stored += 0.5 * (Z[zl, i] * K_stuck[i, j] * Z[zl, j] + Z[zl, n + i] * M[i, j] * Z[zl, n + j])
    stored = max(stored, 0.5 * kdiag * A * A)
    etol = max(energy_rtol * flow, amp_rtol * stored, 1e-300)
    if emax - emin > etol or wmax - wmin > etol:
        return False
    # a periodic motion returns its stored energy: work = dissipation (to
    # balance_rtol: the energy integrals carry the discretisation error)
    btol = max(balance_rtol * flow, amp_rtol * stored)
    if abs(wsum / K - esum / K) > btol:
        return False
    return True


def _check_periodic(h: _History, p: int, model, o: SteadyStateOptions):
    """True if the last K = ``o.check_periods`` windows of p periods repeat within the tolerances.

    Over the last K windows of p periods: the half peak-to-peak amplitudes
    agree within ``o.amp_rtol`` of the amplitude, so do the Poincare points
    (state one window apart; velocities scaled by w), the energy dissipated
    and the work of the forcing per period within ``o.energy_rtol`` of the
    energy flow, and work equals dissipation within ``o.balance_rtol``.
    """
    K = o.check_periods
    if h.size < K * p:
        return False
    return bool(_periodic_arrays(h.summ, h.Z, p, K, model.n, model.w, model.pack.K_stuck, model.pack.M,
                                 _amplitude_scale(model, 0.0), o.amp_rtol, o.energy_rtol, o.balance_rtol))  # fmt: skip


def _growing(h: _History, model, o: SteadyStateOptions) -> bool:
    """Amplitude increasing over the last ``o.growth_periods`` periods without slowing down."""
    G = o.growth_periods
    if h.size < G + 1:
        return False
    S = np.asarray(h.summ[-(G + 1):])
    A = 0.5 * (S[:, S_XMAX] - S[:, S_XMIN])
    d = np.diff(A)
    if not np.all(d > 0):
        return False
    half = d.size // 2
    if d[half:].mean() < o.growth_ratio * d[:half].mean():
        return False
    # energy surplus (W - E_c - E_v) / W per period: stays positive and does
    # not decay when the response is unbounded (Den Hartog: 1 - 4R/(pi F));
    # it decays to 0 on a (slow) approach to a bounded state
    sur = (S[1:, S_W] - S[1:, S_EC] - S[1:, S_EV]) / np.maximum(np.abs(S[1:, S_W]), 1e-300)
    q = max(sur.size // 4, 1)
    if not np.all(sur > 0) or sur[-q:].mean() < o.growth_ratio * sur[:q].mean():
        return False
    if d.mean() <= o.amp_rtol * A[-1]:
        return False
    # a contact in microslip dissipates ~A^3 (faster than the work ~A of the
    # forcing): growth can only be unbounded once the friction saturates
    laws = model.pack.laws
    if laws and not A[-1] > o.unbounded_q * laws[0].fy / laws[0].kt:
        return False
    return True


def _long_period(h: _History, model, o: SteadyStateOptions) -> int:
    """Smallest multiple p in (``o.max_multiple``, ``o.detect_multiple``] that repeats (0 if none)."""
    K = o.check_periods
    for p in range(o.max_multiple + 1, o.detect_multiple + 1):
        if h.size < K * p:
            break
        if _check_periodic(h, p, model, o) and not _one_period_decaying(h, K * p, model, o.multiple_decay):
            return p
    return 0


def _one_period_decaying(h: _History, m: int, model, decay: float) -> bool:
    """True unless the one-period mismatch of the Poincare points has stopped decaying.

    A genuine p-periodic orbit repeats its one-period mismatches exactly; a
    slowly decaying beat that happens to be nearly commensurate with the
    forcing (lightly damped transients) shrinks them. Compares the largest
    mismatch over the last m periods with that over the m periods before
    (needs 2m periods of history; undecided counts as decaying): decaying when the later is below
    ``decay`` times the earlier (``SteadyStateOptions.multiple_decay``).
    """
    if h.size < 2 * m:
        return True
    d = _mismatches(h, 2 * m, model)
    return d[m:].max() < decay * d[:m].max()


def _mismatches(h: _History, count: int, model) -> np.ndarray:
    """Largest one-period change of the period-boundary state over the last
    ``count`` periods (velocities scaled by 1/w to displacement units)."""
    D = np.diff(h.Z[-(count + 1):], axis=0)
    D[:, model.n:] /= max(model.w, 1e-300)
    return np.max(np.abs(D), axis=1)


def _stalled(h: _History, model, o: SteadyStateOptions) -> bool:
    """True when the one-period mismatch has stopped shrinking (quasi-periodic, chaotic).

    Compares the largest mismatch over the last ``o.stall_periods`` / 2 periods
    with that over the half before.
    """
    m = o.stall_periods // 2
    if h.size < 2 * m:
        return False
    d = _mismatches(h, 2 * m, model)
    return d[m:].max() >= o.stall_ratio * d[:m].max()


def _contraction(h: _History, model):
    """Estimated contraction factor of the Poincare distance per period (or None)."""
    if h.size < 6:
        return None
    Z = np.asarray(h.Z[-7:])
    n = model.n
    D = np.diff(Z, axis=0)
    D[:, n:] /= max(model.w, 1e-300)
    d = np.max(np.abs(D), axis=1)
    if d[0] <= 0 or d[-1] <= 0:
        return None
    return (d[-1] / d[0]) ** (1.0 / (d.size - 1)), d[-1]


def _booker(counters):
    """``count(result, fraction=1)``: books the periods and steps of a run into ``counters``."""

    def count(res, frac=1.0):
        counters["periods"] += res.done * frac
        counters["steps"] += int(res.summary[:, S_STEPS].sum()) if res.done else 0

    return count


def _section(model: Model, x, v, S, rdof, count, clean: bool):
    """Move to the Poincare section of shooting; returns (x, v, S, grid of one
    period from there, section time s), or None on a blow-up.

    The section is at phase 0, or in the middle of a separation when every
    contact separates (law states reset there, so (x, v) is the whole state
    and the map is exact); at phase 0 the law states are first rebuilt from
    the last period alone where ``clean`` (``SteadyStateOptions.shoot_clean_state``).
    """
    ts = model.section_time()
    if ts > 0.0:
        res = model.run_grid(x, v, S, model.segment_grid(0.0, ts), 1, rdof)
        count(res, ts / model.period)
        if not res.status.ok:
            return None
        return x, v, S, model.segment_grid(ts, ts + model.period), ts
    if clean and model.nc:
        cl = clean_states(model, x, v, S, rdof, count)
        if cl is None:
            return None
        x, v, S = cl
    return x, v, S, model.grid, ts


def _line_search(phi, z, dz, D, S1, rn, o: SteadyStateOptions):
    """Damped Newton step: the first of z + lam dz D (lam = 1, 1/2, ... ``o.shoot_halvings`` times;
    |lam dz| <= ``o.shoot_maxstep``) whose residual is below ``rn``; None if none is."""
    lam = 1.0
    big = float(np.max(np.abs(dz)))
    if big > o.shoot_maxstep:
        lam = o.shoot_maxstep / big
    for _ls in range(o.shoot_halvings):
        zn = z + lam * dz * D
        zn1, Sn1, sn1 = phi(zn, S1)
        if zn1 is not None:
            rnew = np.max(np.abs((zn1 - zn) / D))
            if rnew < rn:
                return zn, zn1, Sn1, sn1
        lam *= 0.5
    return None


def _newton(model: Model, phi, z, S, tol, counters, o: SteadyStateOptions):
    """Newton on the period map from (z, S); returns (z, S, converged, floquet_max)
    (converged False also when the period map blows up).

    Residuals are compared in the scale of the first iterate, so that a step
    that merely inflates the amplitude (a relative residual shrinking because
    the scale grows: an undamped resonance) is never taken for progress. A
    stalled Newton (noise of the non-smooth law) may still have removed most
    of the transient: its best iterate is kept if it gained a factor of 100
    (the integration that follows decides).
    """
    n, w = model.n, model.w
    floq = math.nan
    z1, S1, s1 = phi(z, S)
    if z1 is None:
        return z, S, False, floq
    best = None  # (residual, z, S, first residual) in the fixed scale D0
    D0 = None
    for _ in range(o.shoot_maxit):
        A = 0.5 * (s1[S_XMAX] - s1[S_XMIN])
        xs = _amplitude_scale(model, max(A, np.max(np.abs(z[:n]))))
        D = np.concatenate([np.full(n, xs), np.full(n, xs * w)])
        if D0 is None:
            D0 = D
        r = (z1 - z) / D0
        rn = float(np.max(np.abs(r)))
        if best is None or rn < best[0]:
            best = (rn, z.copy(), S.copy(), rn if best is None else best[3])
        if float(np.max(np.abs((z1 - z) / D))) <= tol:
            return z, S, True, floq
        D = D0
        counters["shoot"] += 1
        Jm = fd_monodromy(lambda zz: phi(zz, S)[0], z, D, o.shoot_fd, z1)
        if Jm is None:
            return z, S, False, floq
        floq = float(np.max(np.abs(np.linalg.eigvals(Jm))))
        dz = np.linalg.lstsq(Jm - np.eye(2 * n), -r, rcond=1e-8)[0]
        step = _line_search(phi, z, dz, D, S1, rn, o)
        if step is None:
            break
        z, S, z1, S1, s1 = step[0], S1, step[1], step[2], step[3]
    if best is None or not best[0] <= 1e-2 * best[3]:
        return z, S, False, floq
    return best[1], best[2], True, floq


def _shoot(model: Model, x, v, S, rdof, tol, counters, o: SteadyStateOptions):
    """Newton on the period map (x, v) -> (x, v)(t + T) with the law state carried.

    The finite-difference monodromy (:func:`~jointdyn.dynamics.monodromy.fd_monodromy`,
    forward differences) perturbs (x, v) with the law state kept (a
    displacement perturbation acts as a motion of the contact); the steps
    are minimum-norm (least squares), because the offset of a partly stuck
    contact is neutral. Returns (x, v, S, converged, floquet_max) at a
    phase-0 boundary. ``counters`` (dict) gets the periods, steps and
    iterations spent.
    """
    n = model.n
    x0, v0, S0 = x.copy(), v.copy(), S.copy()
    count = _booker(counters)
    sec = _section(model, x, v, S, rdof, count, o.shoot_clean_state)
    if sec is None:
        return x0, v0, S0, False, math.nan
    x, v, S, grid, ts = sec

    def phi(zz, SS):
        xx, vv, S2 = zz[:n].copy(), zz[n:].copy(), SS.copy()
        res = model.run_grid(xx, vv, S2, grid, 1, rdof)
        count(res)
        if not res.status.ok or res.done < 1:
            return None, None, None
        return np.concatenate([xx, vv]), S2, res.summary[0]

    z, S, ok, floq = _newton(model, phi, np.concatenate([x, v]), S, tol, counters, o)
    if not ok:
        return x0, v0, S0, False, floq
    x = z[:n].copy()
    v = z[n:].copy()
    if ts > 0.0:
        res = model.run_grid(x, v, S, model.segment_grid(ts, model.period), 1, rdof)
        count(res, (model.period - ts) / model.period)
        if not res.status.ok:
            return x0, v0, S0, False, floq
    return x, v, S, True, floq


def _unpack_start(start, model):
    if isinstance(start, SteadyState):
        start = start.restart
    if not isinstance(start, Restart):
        raise ValueError(f"start must be None, a SteadyState or a Restart, got {type(start).__name__}")
    x = np.array(start.x, dtype=float)
    v = np.array(start.v, dtype=float)
    S = np.array(start.states, dtype=float, ndmin=2)
    if x.shape != (model.n,) or v.shape != (model.n,) or S.shape != (model.pack.state_rows, model.pack.slen):
        raise ValueError("start does not belong to this system (shapes of x, v or law states differ)")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError("start must be finite (NaN/inf in its x or v)")
    return x, v, np.ascontiguousarray(S)


@dataclass
class _March:
    """The working state of :func:`steady_state` (mutable; never returned)."""

    x: np.ndarray
    v: np.ndarray
    S: np.ndarray
    hist: _History
    counters: dict
    o: SteadyStateOptions
    shots: int = 0
    floq: float = math.nan

    def shoot(self, model, rdof) -> bool:
        """One shooting attempt; the state and a fresh history are kept if it
        converged to a stable orbit (the largest multiplier is always kept)."""
        self.shots += 1
        xs_, vs_, Ss_, ok, self.floq = _shoot(model, self.x.copy(), self.v.copy(), self.S.copy(), rdof,
                                              0.1 * self.o.amp_rtol, self.counters, self.o)  # fmt: skip
        if ok and not (self.floq > 1.0 + self.o.floquet_tol):
            self.x, self.v, self.S = xs_, vs_, np.ascontiguousarray(Ss_)
            self.hist = _History(np.concatenate([self.x, self.v]))
            return True
        return False


def _period_multiple(hist, model, o: SteadyStateOptions) -> int:
    """Smallest p <= ``o.max_multiple`` with which the history repeats (0 if none);
    a multiple p > 1 must not be a slowly alternating approach to period 1."""
    for p in range(1, o.max_multiple + 1):
        if _check_periodic(hist, p, model, o):
            if p > 1 and _one_period_decaying(hist, o.check_periods * p, model, o.multiple_decay):
                continue
            return p
    return 0


def _need_shoot(hist, model, growing, chunk, o: SteadyStateOptions) -> bool:
    """Shoot when the estimated number of periods to converge exceeds
    ``o.shoot_after``, when the distance does not contract, or when growing."""
    est = _contraction(hist, model)
    if est is None:
        return False
    rho, dlast = est
    A = 0.5 * (hist.summ[-1][S_XMAX] - hist.summ[-1][S_XMIN])
    target = o.amp_rtol * _amplitude_scale(model, A)
    if growing:
        return True
    if rho >= 1.0:
        return hist.size >= 2 * chunk
    if dlast > target:
        return math.log(target / dlast) / math.log(rho) > o.shoot_after
    return False


def _settle(model, st: _March, rdof, shooting):
    """Integrate chunks of periods (shooting over slow transients) until classified.

    Once a normal spring opens, the model is replaced by its refined twin
    (:func:`~jointdyn.dynamics._model.refine_if_opened`) and the history
    starts again. Returns (status or None when max_periods ran out, detail,
    p, the model in use); the numbers are ``st.o``'s.
    """
    o = st.o
    maxp = o.max_periods
    chunk = max(o.chunk, o.check_periods)
    while True:
        nrun = int(min(chunk, maxp - st.counters["periods"]))
        if nrun <= 0:
            return None, "", 0, model
        res = model.run_periods(st.x, st.v, st.S, nrun, rdof=rdof)
        _booker(st.counters)(res)
        st.hist.add(res.summary, res.z_end, res.pairs)
        if not res.status.ok:
            return SteadyStatus.UNBOUNDED, "blow-up", 0, model
        finer = refine_if_opened(model, res.summary)
        if finer is not None:
            model, st.hist = finer, _History(np.concatenate([st.x, st.v]))
            continue
        p_found = _period_multiple(st.hist, model, o)
        long_p = 0 if p_found else _long_period(st.hist, model, o)
        growing = False if (p_found or long_p) else _growing(st.hist, model, o)
        can_shoot = shooting and st.shots < o.max_shots
        # a multiple p > 1 may be a lightly damped transient whose free
        # frequency is commensurate with the forcing: first look for a
        # stable period-1 orbit by shooting (once per history)
        if (p_found > 1 or long_p) and can_shoot and not st.hist.shot_checked:
            st.hist.shot_checked = True
            if st.shoot(model, rdof):
                continue
        if p_found:
            return SteadyStatus.PERIODIC, "shooting" if st.counters["shoot"] else "integration", p_found, model
        if long_p:
            return SteadyStatus.NOT_SETTLED, f"period-{long_p}", 0, model
        if growing and not can_shoot:
            return SteadyStatus.UNBOUNDED, "growing", 0, model
        if st.counters["periods"] >= maxp or (not can_shoot and _stalled(st.hist, model, o)):
            return None, "", 0, model
        if can_shoot and _need_shoot(st.hist, model, growing, chunk, o):
            st.shoot(model, rdof)


def _periodic_values(model, st: _March, p, rdof, keep_loop):
    """Amplitude, offset, energies of the final p periods (and the recorded loop)."""
    if keep_loop:
        res = model.run_periods(st.x, st.v, st.S, p, rec=True, rdof=rdof)
        _booker(st.counters)(res)
        loop = _trajectory(res, st.x, st.v, st.S)
        summ, pairs = res.summary, res.pairs
    else:
        loop = None
        summ = np.asarray(st.hist.summ[-p:])
        pairs = np.asarray(st.hist.pairs[-p:]) if model.pack.npairs else np.zeros((p, 0, 4))
    A = 0.5 * (summ[:, S_XMAX].max() - summ[:, S_XMIN].min())
    vals = {"amplitude_m": float(A), "amplitude_q": math.nan}
    if model.pack.laws:
        law = model.pack.laws[0]
        vals["amplitude_q"] = float(law.kt * A / law.fy) if law.fy > 0 else math.inf
    vals["offset_m"] = float(summ[:, S_XMEAN].mean())
    vals["max_abs_m"] = float(max(abs(summ[:, S_XMAX].max()), abs(summ[:, S_XMIN].min())))
    vals["energy_contact_J"] = float(summ[:, S_EC].mean())
    vals["energy_viscous_J"] = float(summ[:, S_EV].mean())
    vals["work_force_J"] = float(summ[:, S_W].mean())
    for col, key in enumerate(("pair_energy_J", "pair_stick", "pair_slip", "pair_open")):
        vals[key] = pairs[:, :, col].mean(axis=0)
    return vals, loop


def steady_state(
    system: System,
    gamma: float,
    *,
    steps_per_period: int | None = None,
    start=None,
    amp_rtol: float | None = None,
    energy_rtol: float | None = None,
    check_periods: int | None = None,
    max_periods: int | None = None,
    response_dof: int | None = None,
    keep_loop: bool = True,
    shooting: bool = True,
    options: SteadyStateOptions | None = None,
    _events: bool = True,
) -> SteadyState:
    """Steady periodic response at frequency ratio ``gamma``, classified.

    Integrates M x'' + C x' + K x = f sin(w t) - sum_c B_c T_c(u_c, N_c(t))
    (docs/model.md section 6), w = gamma w0, until the response repeats with the
    forcing period or a multiple p <= ``options.max_multiple``: over the
    last ``check_periods`` windows of p periods the half peak-to-peak
    amplitude of x[response_dof] and the period-boundary state agree within
    ``amp_rtol`` (relative to the amplitude) and the dissipated energy and
    the work of the forcing per period within ``energy_rtol``. Slowly
    decaying transients are skipped by shooting (Newton on the period map).

    Parameters
    ----------
    system : System
        The forced system.
    gamma : float
        w / w0 (> 0).
    steps_per_period : int, optional
        Base RK4 steps per forcing period (default ``options.march.steps_per_period``, 256).
    start : SteadyState or Restart, optional
        Warm start (state at a period boundary, e.g. the previous sweep
        point). Default: equivalent-linearisation estimate (stuck stiffness
        kt refined by the law's describing function).
    amp_rtol, energy_rtol : float, optional
        Tolerances (defaults ``options.amp_rtol``, 1e-4, and ``options.energy_rtol``, 1e-3).
    check_periods : int, optional
        K, windows that must agree (default ``options.check_periods``, 3).
    max_periods : int, optional
        Cap on integrated periods (default ``options.max_periods``, 1500).
    response_dof : int, optional
        DOF whose amplitude is reported (default: the system's response DOF,
        ``[output] dof`` of a system file, as :func:`jointdyn.frc_hb`,
        :func:`jointdyn.frc_sweep` and the CLI report).
    keep_loop : bool
        Record the final p periods in ``loop``.
    shooting : bool
        Allow shooting to skip slow transients.
    options : SteadyStateOptions, optional
        Every number of the steady state (:class:`~jointdyn.dynamics.options.SteadyStateOptions`;
        None: the defaults); the keyword arguments above, where given, replace its fields.

    Returns
    -------
    SteadyState
        With ``status`` (:class:`SteadyStatus`) "periodic", "not-settled" or
        "unbounded"; amplitudes are NaN unless periodic.
    """
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    o = steady_options(options)
    march = None if steps_per_period is None else march_with_steps(o.march, steps_per_period)
    o = _resolved(o, march=march, amp_rtol=amp_rtol, energy_rtol=energy_rtol, check_periods=check_periods,
                  max_periods=max_periods)
    rdof = V.positive_int("response_dof", system.response_dof if response_dof is None else response_dof, 0)
    if rdof >= system.ndof:
        raise ValueError(f"response_dof must be in [0, {system.ndof - 1}], got {rdof}")
    w = _omega(system, gamma)
    model = make_model(system, w, o.march, events=_events)
    x, v, S = _first_state(model, start, o)
    st = _March(x, v, S, _History(np.concatenate([x, v])), {"periods": 0, "steps": 0, "shoot": 0}, o)
    status, detail, p_found, model = _settle(model, st, rdof, shooting)
    if status is None:
        # did not settle within max_periods: say why if we can
        status = SteadyStatus.NOT_SETTLED
        stalled = st.hist.size >= o.stall_periods and _stalled(st.hist, model, o)
        detail = "quasi-periodic-or-chaotic" if stalled else "slowly-converging"
    last = st.hist.summ[-1] if st.hist.size else None
    last_amp = 0.5 * (last[S_XMAX] - last[S_XMIN]) if last is not None else math.nan
    nan = math.nan
    vals = dict(amplitude_q=nan, amplitude_m=nan, offset_m=nan, max_abs_m=nan,
                energy_contact_J=nan, energy_viscous_J=nan, work_force_J=nan)  # fmt: skip
    for key in ("pair_energy_J", "pair_stick", "pair_slip", "pair_open"):
        vals[key] = np.full(model.pack.npairs, nan)
    loop, check = None, EnergyCheck.NOT_CHECKED
    if status.ok:
        vals, loop = _periodic_values(model, st, p_found, rdof, keep_loop)
        check = energy_check(vals["work_force_J"], vals["energy_contact_J"], vals["energy_viscous_J"])
        if check is EnergyCheck.NEGATIVE_DISSIPATION:
            warnings.warn(f"steady_state at gamma {gamma:g}: the contact dissipates {vals['energy_contact_J']:.3e} J "
                          f"per period (< 0 beyond the energy-balance residual): {check.message}",
                          RuntimeWarning, stacklevel=2)  # fmt: skip
    return SteadyState(
        status=status, message=detail, period_multiple=int(p_found), gamma=float(gamma), omega=w,
        periods=int(math.ceil(st.counters["periods"])), steps=int(st.counters["steps"]),
        shooting_iterations=int(st.counters["shoot"]), floquet_max=float(st.floq), energy_check=check,
        last_amplitude_m=float(last_amp), restart=Restart(st.x.copy(), st.v.copy(), st.S.copy()), loop=loop,
        **vals,
    )  # fmt: skip


def energy_check(work_force_J: float, energy_contact_J: float, energy_viscous_J: float) -> EnergyCheck:
    """Passivity of the contacts over a periodic orbit, from its energies per period (J).

    Flags ``energy_contact_J < -tol`` with ``tol = |W - E_contact -
    E_viscous| + SS_DISSIPATION_FLOOR (|W| + |E_contact| +
    |E_viscous|)``: the period's energy-balance residual bounds the
    quadrature and transient error of the contact's integral, so a value
    beyond it is energy created by the contact law.

    Returns
    -------
    EnergyCheck
        ``PASSIVE`` or ``NEGATIVE_DISSIPATION``.
    """
    W, Ec, Ev = float(work_force_J), float(energy_contact_J), float(energy_viscous_J)
    tol = abs(W - Ec - Ev) + SS_DISSIPATION_FLOOR * (abs(W) + abs(Ec) + abs(Ev))
    return EnergyCheck.NEGATIVE_DISSIPATION if Ec < -tol else EnergyCheck.PASSIVE


def prepare_kernels(systems) -> None:
    """Compile, or load from the disk cache, the kernels :func:`steady_state` runs for ``systems``.

    Process pools call this before they fork, so that their workers inherit
    the compiled code: each would otherwise compile (or load) the same
    kernels at the same time (on a cold cache, k workers compile everything
    k times). For the first system of each set of kernels (law kernels,
    springs, forcing phases) it runs, at gamma = 1, the
    equivalent-linearisation start, one period of the step grid, the
    rebuilding of the law states from it and the periodicity test on a
    history too short to pass: milliseconds once compiled. A system that
    steady_state refuses (ValueError) is left to the solve that reports it.
    """
    seen, o = set(), SteadyStateOptions()
    for system in systems:
        pack = pack_system(system)
        if (pack.runner, pack.init) in seen:
            continue
        seen.add((pack.runner, pack.init))
        try:
            model = make_model(system, _omega(system, 1.0), o.march)
        except ValueError:
            continue
        x, v, S = _first_state(model, None, o)
        clean_states(model, x, v, S, 0, lambda res: None)
        _periodic_arrays(np.empty((0, N_SUMMARY)), np.zeros((1, 2 * model.n)), 1, o.check_periods, model.n,
                         model.w, model.pack.K_stuck, model.pack.M, _amplitude_scale(model, 0.0), o.amp_rtol,
                         o.energy_rtol, o.balance_rtol)  # fmt: skip


def _resolved(o: SteadyStateOptions, **given) -> SteadyStateOptions:
    """``o`` with the fields given as keyword arguments (not None) replaced, each validated by its name."""
    given = {k: v for k, v in given.items() if v is not None}
    return dataclasses.replace(o, **given) if given else o


def _first_state(model, start, o: SteadyStateOptions):
    """(x, v, S) to start from: the warm start, else the equivalent-linearisation
    estimate, else rest with virgin law states; a free-free structure's rigid-body part, whatever the
    start, at the periodic motion of the free body at this frequency (:func:`free_body_start`: no drift)."""
    if start is not None:
        x, v, S = _unpack_start(start, model)
    else:
        est = linear_start(model, o.linear_iters, o.linear_rtol)
        if est is None:
            x = np.zeros(model.n)
            x, v, S = x, np.zeros(model.n), model.initial_states(x)
        else:
            x, v, S = est
    x, v = free_body_start(model, x, v)
    return x, v, np.ascontiguousarray(S)
