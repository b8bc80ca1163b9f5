"""Steady periodic response of a harmonically forced System, with classification.

:func:`steady_state` integrates (RK4 core, ``_core.py``) until the response
repeats with the forcing period, or with a multiple p <= 4 of it, within
tolerances on the half peak-to-peak amplitude, the period-boundary state
(Poincare points) and the energy per period over K windows; otherwise it
classifies the run as ``"unbounded"`` (amplitude still growing, e.g. the Den
Hartog case of MODEL.md section 6) or ``"not-settled"``. When the transient
decays slowly (lightly damped cases, MODEL.md section 7) it computes the
periodic state directly by shooting: Newton on the period map of (x, v) with
the law state carried along, finite-difference monodromy matrix, minimum-norm
(least-squares) steps because the offset of a partly stuck contact is
neutral (a multiplier 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V
from .. import config
from .._jit import jit, specialize
from ..drivers import march
from ..systems import System
from ._core import grid_loads
from ._core import N_SUMMARY, S_EC, S_EV, S_STEPS, S_W, S_XMAX, S_XMEAN, S_XMIN
from .integrate import Restart, Trajectory, _Model, _omega

__all__ = ["SteadyState", "steady_state", "STATUSES"]

#: possible values of :attr:`SteadyState.status`
STATUSES = ("periodic", "not-settled", "unbounded")


@dataclass(frozen=True)
class SteadyState:
    """Result of :func:`steady_state`.

    Every amplitude/energy field is NaN unless ``status == "periodic"``: a
    run that did not settle is never reported as a plain number (the last
    observed amplitude is kept in ``last_amplitude_m`` for diagnostics).

    Attributes
    ----------
    status : str
        ``"periodic"``, ``"not-settled"`` or ``"unbounded"``.
    detail : str
        More on the status: ``"integration"`` or ``"shooting"`` (how a
        periodic state was reached); ``"growing"``, ``"blow-up"``
        (unbounded); ``"period-P"`` (repeats every P > SS_MAX_MULTIPLE
        periods), ``"slowly-converging"`` (Poincare distance still
        shrinking at max_periods), ``"quasi-periodic-or-chaotic"`` (the
        one-period mismatch stopped shrinking over SS_STALL_PERIODS periods,
        after shooting; quasi-periodic and chaotic are not told apart).
    period_multiple : int
        p: the response repeats every p forcing periods (0 if not periodic).
    gamma, omega : float
        Frequency ratio w / w0 and excitation frequency w (rad/s).
    amplitude_q : float
        kt X / fy of the first contact's law (MODEL.md section 6).
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
    last_amplitude_m : float
        Half peak-to-peak of the last integrated period, m (diagnostic; not a result).
    restart : Restart
        x, v and law states at the final period boundary (warm start).
    loop : Trajectory or None
        The final p periods, sampled at every step (if ``keep_loop``).
    """

    status: str
    detail: str
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
    last_amplitude_m: float
    restart: Restart = field(repr=False)
    loop: Trajectory | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """True when a periodic steady state was found."""
        return self.status == "periodic"

    def to_record(self) -> dict:
        """The scalar fields as a flat dict (one row of a sweep table)."""
        keys = (
            "status", "detail", "period_multiple", "gamma", "omega", "amplitude_q", "amplitude_m",
            "offset_m", "max_abs_m", "energy_contact_J", "energy_viscous_J", "work_force_J",
            "periods", "steps", "shooting_iterations", "floquet_max", "last_amplitude_m",
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
        self.shot_checked = False

    def add(self, summ, zend):
        self.summ = np.concatenate([self.summ, summ])
        self.Z = np.concatenate([self.Z, zend])

    @property
    def size(self):
        return len(self.summ)


def _amplitude_scale(model, A):
    floor = 1e-14 + 1e-9 * sum(c.law.fy / c.law.kt for c in model.system.contacts)
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


def _check_periodic(h: _History, p: int, K: int, model, amp_rtol, energy_rtol):
    """True if the last K windows of p periods repeat within the tolerances.

    Over the last K windows of p periods: the half peak-to-peak amplitudes
    agree within ``amp_rtol`` of the amplitude, so do the Poincare points
    (state one window apart; velocities scaled by w), the energy dissipated
    and the work of the forcing per period within ``energy_rtol`` of the
    energy flow, and work equals dissipation within ``SS_BALANCE_RTOL``.
    """
    if h.size < K * p:
        return False
    return bool(_periodic_arrays(h.summ, h.Z, p, K, model.n, model.w, model.K_stuck, model.M,
                                 _amplitude_scale(model, 0.0), amp_rtol, energy_rtol, config.SS_BALANCE_RTOL))  # fmt: skip


def _growing(h: _History, model, amp_rtol) -> bool:
    """Amplitude increasing over the last SS_GROWTH_PERIODS periods without slowing down."""
    G = config.SS_GROWTH_PERIODS
    if h.size < G + 1:
        return False
    S = np.asarray(h.summ[-(G + 1):])
    A = 0.5 * (S[:, S_XMAX] - S[:, S_XMIN])
    d = np.diff(A)
    if not np.all(d > 0):
        return False
    half = d.size // 2
    if d[half:].mean() < config.SS_GROWTH_RATIO * d[:half].mean():
        return False
    # energy surplus (W - E_c - E_v) / W per period: stays positive and does
    # not decay when the response is unbounded (Den Hartog: 1 - 4R/(pi F));
    # it decays to 0 on a (slow) approach to a bounded state
    sur = (S[1:, S_W] - S[1:, S_EC] - S[1:, S_EV]) / np.maximum(np.abs(S[1:, S_W]), 1e-300)
    q = max(sur.size // 4, 1)
    if not np.all(sur > 0) or sur[-q:].mean() < config.SS_GROWTH_RATIO * sur[:q].mean():
        return False
    if d.mean() <= amp_rtol * A[-1]:
        return False
    # a contact in microslip dissipates ~A^3 (faster than the work ~A of the
    # forcing): growth can only be unbounded once the friction saturates
    cs = model.system.contacts
    if cs and not A[-1] > config.SS_UNBOUNDED_Q * cs[0].law.fy / cs[0].law.kt:
        return False
    return True


def _long_period(h: _History, K: int, model, amp_rtol, energy_rtol) -> int:
    """Smallest multiple p in (SS_MAX_MULTIPLE, SS_DETECT_MULTIPLE] that repeats (0 if none)."""
    for p in range(config.SS_MAX_MULTIPLE + 1, config.SS_DETECT_MULTIPLE + 1):
        if h.size < K * p:
            break
        if _check_periodic(h, p, K, model, amp_rtol, energy_rtol) and not _one_period_decaying(h, K * p, model):
            return p
    return 0


def _one_period_decaying(h: _History, m: int, model) -> bool:
    """True unless the one-period mismatch of the Poincare points has stopped decaying.

    A genuine p-periodic orbit repeats its one-period mismatches exactly; a
    slowly decaying beat that happens to be nearly commensurate with the
    forcing (lightly damped transients) shrinks them. Compares the largest
    mismatch over the last m periods with that over the m periods before
    (needs 2m periods of history; undecided counts as decaying).
    """
    if h.size < 2 * m:
        return True
    d = _mismatches(h, 2 * m, model)
    return d[m:].max() < config.SS_MULTIPLE_DECAY * d[:m].max()


def _mismatches(h: _History, count: int, model) -> np.ndarray:
    """Largest one-period change of the period-boundary state over the last
    ``count`` periods (velocities scaled by 1/w to displacement units)."""
    D = np.diff(h.Z[-(count + 1):], axis=0)
    D[:, model.n:] /= max(model.w, 1e-300)
    return np.max(np.abs(D), axis=1)


def _stalled(h: _History, model) -> bool:
    """True when the one-period mismatch has stopped shrinking (quasi-periodic, chaotic).

    Compares the largest mismatch over the last SS_STALL_PERIODS / 2 periods
    with that over the half before.
    """
    m = config.SS_STALL_PERIODS // 2
    if h.size < 2 * m:
        return False
    d = _mismatches(h, 2 * m, model)
    return d[m:].max() >= config.SS_STALL_RATIO * d[:m].max()


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


def _df_template(Z0, f, B, kt, P, sin_th, cos_th, loads, ns, iters, rtol, xmax, S_out, X_out):  # pragma: no cover - compiled
    """Describing-function iteration of :func:`_linear_start`, compiled (``STEP``, ``INIT`` bound).

    Returns False if the iteration diverges (non-finite or absurdly large X);
    else writes X (complex amplitudes, m) and the law states after the
    two-cycle march of the final estimate. ``np.linalg.solve`` raises
    ``LinAlgError`` for a singular dynamic stiffness.
    """
    n = f.shape[0]
    nc = B.shape[0]
    L = sin_th.shape[0]
    slen = S_out.shape[1]
    kc = np.zeros(nc, dtype=np.complex128)
    for i in range(nc):
        kc[i] = kt[i]
    X = np.zeros(n, dtype=np.complex128)
    U = np.zeros(nc, dtype=np.complex128)
    Z = np.zeros((n, n), dtype=np.complex128)
    sa = np.zeros(slen)
    sb = np.zeros(slen)
    have = False
    final = False
    it = 0
    while True:
        if not final:
            for a in range(n):
                for b in range(n):
                    Z[a, b] = Z0[a, b]
            for i in range(nc):
                for a in range(n):
                    for b in range(n):
                        Z[a, b] += B[i, a] * kc[i] * B[i, b]
            Xn = np.linalg.solve(Z, f)
            big = 0.0
            diff = 0.0
            for a in range(n):
                if not (np.isfinite(Xn[a].real) and np.isfinite(Xn[a].imag)):
                    return False
                big = max(big, abs(Xn[a]))
                diff = max(diff, abs(Xn[a] - X[a]))
            if big > xmax:
                return False
            conv = have and diff <= rtol * big
            for a in range(n):
                X[a] = Xn[a]
            have = True
            it += 1
            final = conv or it >= iters
        for i in range(nc):
            acc = 0.0 + 0.0j
            for a in range(n):
                acc += B[i, a] * X[a]
            U[i] = acc
        for i in range(nc):
            if U[i] == 0 and not final:
                continue
            ur = U[i].real
            ui = U[i].imag
            INIT(P[i], ur * sin_th[0] + ui * cos_th[0], loads[i, 0], sa)  # noqa: F821 - bound by specialize
            ca = 0.0
            cb = 0.0
            for j in range(L):
                T, _, _ = STEP(P[i], sa, sb, ur * sin_th[j] + ui * cos_th[j], loads[i, j])  # noqa: F821
                sa, sb = sb, sa
                if ns <= j < 2 * ns:
                    ca += T * sin_th[j]
                    cb += T * cos_th[j]
            if final:
                for r in range(slen):
                    S_out[i, r] = sa[r]
            else:
                kc[i] = 0.5 * kc[i] + 0.5 * (2.0 / ns) * (ca + 1j * cb) / U[i]
        if final:
            break
    for a in range(n):
        X_out[a] = X[a]
    return True


# the describing-function march: two cycles of 64 samples ending before t = 0
# (theta = w t), and t = 0 itself; the first harmonic is taken over the second
_DF_NS = 64
_DF_TH = np.append(2 * math.pi * np.arange(2 * _DF_NS) / _DF_NS - 4 * math.pi, 0.0)
_DF_GRID = (_DF_NS, _DF_TH, np.sin(_DF_TH), np.cos(_DF_TH))


def _linear_start(model: _Model):
    """Equivalent-linearisation estimate of the periodic state at phase 0.

    Solves (K - w^2 M + i w C + sum_c k_c B_c B_c^T) X = f with k_c the
    describing function (first harmonic of T over one cycle of
    u = Im(U e^{i w t}) with the actual N_c(t), marched with the real law),
    started from the stuck stiffness kt and iterated with relaxation 1/2
    until X changes by less than ``config.SS_LINEAR_RTOL`` (at most
    ``config.SS_LINEAR_ITERS`` solves). The iteration is one compiled call
    (``_df_template``). Returns x, v (m, m/s) and law states at t = 0 (law
    marched over the last two cycles of the estimate), or None if the
    iteration diverges.
    """
    sysm = model.system
    n, w = model.n, model.w
    Z0 = model.K - w * w * model.M + 1j * w * model.C
    f = model.fvec.astype(np.complex128)
    ns, th, sin_th, cos_th = _DF_GRID
    loads = grid_loads(th, 1.0, model.n0, model.n1, model.dlt).T.copy()
    S = np.zeros((model.nc, model.slen))
    X = np.zeros(n, dtype=np.complex128)
    run = specialize(_df_template, STEP=model.step, INIT=model.init)
    xscale = model.fmax / model.kmin + model.xlin
    try:
        ok = run(Z0, f, model.B, model.kt, model.P, sin_th, cos_th, loads, ns,
                 config.SS_LINEAR_ITERS if model.nc else 1, config.SS_LINEAR_RTOL, 1e3 * xscale, S, X)  # fmt: skip
    except np.linalg.LinAlgError:
        return None
    if not ok:
        return None
    return np.imag(X).copy(), w * np.real(X).copy(), S


def _clean_states(model: _Model, x, v, S, rdof, count):
    """One recorded period, then law states rebuilt from that period alone.

    A slowly decaying transient leaves a long nested sequence of reversal
    points in a Masing law's memory, which makes the state at a period
    boundary differ from period to period even once (x, v) repeat. The law
    is re-marched (drivers.march) from its virgin state over two repetitions
    of the last period's contact displacement and normal load, which keeps
    the current loop and forgets the transient. Returns (x, v, S) at the
    end of the period, or None on a blow-up.
    """
    x = x.copy()
    v = v.copy()
    S = S.copy()
    summ, _, st_, done, smp = model.run_periods(x, v, S, 1, rec=True, rdof=rdof)
    count(summ, done)
    if st_ != 0 or done < 1:
        return None
    _, X, _, _, N, _ = smp
    Snew = np.zeros_like(S)
    for i, c in enumerate(model.system.contacts):
        u = X[:, c.dof] - (X[:, c.dof2] if c.dof2 >= 0 else 0.0)
        uu = np.concatenate([u, u[1:]])
        NN = np.concatenate([N[:, i], N[1:, i]])
        s0 = c.law.initial_state(float(uu[0]), float(NN[0]))
        sf = march(c.law, uu, NN, state=s0)[3]
        Snew[i, : sf.size] = sf
    return x, v, np.ascontiguousarray(Snew)


def _shoot(model: _Model, x, v, S, rdof, tol, counters):
    """Newton on the period map (x, v) -> (x, v)(t + T) with the law state carried.

    The Poincare section is at phase 0, or in the middle of a separation
    when every contact separates (law states reset there, so (x, v) is the
    whole state and the map is exact). The finite-difference monodromy
    perturbs (x, v) with the law state kept (a displacement perturbation
    acts as a motion of the contact). Returns (x, v, S, converged,
    floquet_max) at a phase-0 boundary. ``counters`` (dict) gets the
    periods, steps and iterations spent.
    """
    n = model.n
    w = model.w
    Tp = model.period
    floq = math.nan
    ts = model.section_time()
    x0, v0, S0 = x.copy(), v.copy(), S.copy()

    def count(summ, done, frac=1.0):
        counters["periods"] += done * frac
        counters["steps"] += int(summ[:, S_STEPS].sum()) if done else 0

    if ts > 0.0:
        tg, Ng = model.segment_grid(0.0, ts)
        summ, _, st_, done = model.run_grid(x, v, S, tg, Ng, 1, rdof)
        count(summ, done, ts / Tp)
        if st_ != 0:
            return x0, v0, S0, False, floq
        tgp, Ngp = model.segment_grid(ts, ts + Tp)
    else:
        tgp, Ngp = model.tgrid, model.Ngrid
        if config.SS_SHOOT_CLEAN_STATE and model.nc:
            cl = _clean_states(model, x, v, S, rdof, count)
            if cl is None:
                return x0, v0, S0, False, floq
            x, v, S = cl
    z = np.concatenate([x, v])
    sines = model.sines_of(tgp)

    def phi(zz, SS):
        xx = zz[:n].copy()
        vv = zz[n:].copy()
        S2 = SS.copy()
        summ, zend, status, done = model.run_grid(xx, vv, S2, tgp, Ngp, 1, rdof, sines)
        count(summ, done)
        if status != 0 or done < 1:
            return None, None, None
        return np.concatenate([xx, vv]), S2, summ[0]

    z1, S1, s1 = phi(z, S)
    if z1 is None:
        return x0, v0, S0, False, floq
    converged = False
    best = None  # (residual, z, S, first residual) in the fixed scale D0
    D0 = None
    for _ in range(config.SS_SHOOT_MAXIT):
        A = 0.5 * (s1[S_XMAX] - s1[S_XMIN])
        xs = _amplitude_scale(model, max(A, np.max(np.abs(z[:n]))))
        D = np.concatenate([np.full(n, xs), np.full(n, xs * w)])
        if D0 is None:
            # residuals are compared in the scale of the first iterate, so
            # that a step that merely inflates the amplitude (a relative
            # residual shrinking because the scale grows: an undamped
            # resonance) is never taken for progress
            D0 = D
        r = (z1 - z) / D0
        rn = float(np.max(np.abs(r)))
        if best is None or rn < best[0]:
            best = (rn, z.copy(), S.copy(), rn if best is None else best[3])
        if float(np.max(np.abs((z1 - z) / D))) <= tol:
            converged = True
            break
        D = D0
        counters["shoot"] += 1
        Jm = np.empty((2 * n, 2 * n))
        for j in range(2 * n):
            e = config.SS_SHOOT_FD * D[j]
            zp = z.copy()
            zp[j] += e
            zj, _, _ = phi(zp, S)
            if zj is None:
                return x0, v0, S0, False, floq
            Jm[:, j] = (zj - z1) / D / config.SS_SHOOT_FD
        floq = float(np.max(np.abs(np.linalg.eigvals(Jm))))
        dz = np.linalg.lstsq(Jm - np.eye(2 * n), -r, rcond=1e-8)[0]
        # damped step: accept the first that reduces the residual
        lam = 1.0
        accepted = False
        big = float(np.max(np.abs(dz)))
        if big > config.SS_SHOOT_MAXSTEP:
            lam = config.SS_SHOOT_MAXSTEP / big
        for _ls in range(config.SS_SHOOT_HALVINGS):
            zn = z + lam * dz * D
            zn1, Sn1, sn1 = phi(zn, S1)
            if zn1 is not None:
                rnew = np.max(np.abs((zn1 - zn) / D))
                if rnew < rn:
                    accepted = True
                    break
            lam *= 0.5
        if not accepted:
            break
        z, S, z1, S1, s1 = zn, S1, zn1, Sn1, sn1
    if not converged:
        # a stalled Newton (noise of the non-smooth law) may still have
        # removed most of the transient: keep its best iterate if it gained
        # a factor of 100; the integration that follows decides
        if best is None or not best[0] <= 1e-2 * best[3]:
            return x0, v0, S0, False, floq
        z, S = best[1], best[2]
    x = z[:n].copy()
    v = z[n:].copy()
    if ts > 0.0:
        tg, Ng = model.segment_grid(ts, Tp)
        summ, _, st_, done = model.run_grid(x, v, S, tg, Ng, 1, rdof)
        count(summ, done, (Tp - ts) / Tp)
        if st_ != 0:
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
    if x.shape != (model.n,) or v.shape != (model.n,) or S.shape != (model.nc, model.slen):
        raise ValueError("start does not belong to this system (shapes of x, v or law states differ)")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
        raise ValueError("start must be finite (NaN/inf in its x or v)")
    return x, v, np.ascontiguousarray(S)


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
    response_dof: int = 0,
    keep_loop: bool = True,
    shooting: bool = True,
    _events: bool = True,
) -> SteadyState:
    """Steady periodic response at frequency ratio ``gamma``, classified.

    Integrates M x'' + C x' + K x = f sin(w t) - sum_c B_c T_c(u_c, N_c(t))
    (MODEL.md section 6), w = gamma w0, until the response repeats with the
    forcing period or a multiple p <= ``config.SS_MAX_MULTIPLE``: over the
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
        Base RK4 steps per forcing period (default ``config.TI_STEPS_PER_PERIOD``).
    start : SteadyState or Restart, optional
        Warm start (state at a period boundary, e.g. the previous sweep
        point). Default: equivalent-linearisation estimate (stuck stiffness
        kt refined by the law's describing function).
    amp_rtol, energy_rtol : float, optional
        Tolerances (defaults ``config.SS_AMP_RTOL``, ``config.SS_ENERGY_RTOL``).
    check_periods : int, optional
        K, windows that must agree (default ``config.SS_CHECK_PERIODS``).
    max_periods : int, optional
        Cap on integrated periods (default ``config.SS_MAX_PERIODS``).
    response_dof : int
        DOF whose amplitude is reported.
    keep_loop : bool
        Record the final p periods in ``loop``.
    shooting : bool
        Allow shooting to skip slow transients.

    Returns
    -------
    SteadyState
        With ``status`` "periodic", "not-settled" or "unbounded"; amplitudes
        are NaN unless periodic.
    """
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    spp = V.positive_int(
        "steps_per_period", config.TI_STEPS_PER_PERIOD if steps_per_period is None else steps_per_period, 4
    )
    amp_rtol = V.positive("amp_rtol", config.SS_AMP_RTOL if amp_rtol is None else amp_rtol)
    energy_rtol = V.positive("energy_rtol", config.SS_ENERGY_RTOL if energy_rtol is None else energy_rtol)
    K = V.positive_int("check_periods", config.SS_CHECK_PERIODS if check_periods is None else check_periods, 2)
    maxp = V.positive_int("max_periods", config.SS_MAX_PERIODS if max_periods is None else max_periods)
    rdof = V.positive_int("response_dof", response_dof, 0)
    if rdof >= system.ndof:
        raise ValueError(f"response_dof must be in [0, {system.ndof - 1}], got {rdof}")
    w = _omega(system, gamma)
    gamma = float(gamma)
    model = _Model(system, w, spp, events=_events)

    if start is not None:
        x, v, S = _unpack_start(start, model)
    else:
        est = _linear_start(model)
        if est is None:
            x = np.zeros(model.n)
            v = np.zeros(model.n)
            S = model.initial_states(x)
        else:
            x, v, S = est
            S = np.ascontiguousarray(S)

    counters = {"periods": 0, "steps": 0, "shoot": 0}
    hist = _History(np.concatenate([x, v]))
    status, detail, p_found = None, "", 0
    shots = 0
    floq = math.nan
    pmax = config.SS_MAX_MULTIPLE
    chunk = max(config.SS_CHUNK, K)
    while True:
        nrun = int(min(chunk, maxp - counters["periods"]))
        if nrun <= 0:
            break
        summ, zend, st, done, _ = model.run_periods(x, v, S, nrun, rdof=rdof)
        counters["periods"] += done
        counters["steps"] += int(summ[:, S_STEPS].sum()) if done else 0
        hist.add(summ, zend)
        if st != 0:
            status, detail = "unbounded", "blow-up"
            break
        for p in range(1, pmax + 1):
            if _check_periodic(hist, p, K, model, amp_rtol, energy_rtol):
                if p > 1 and _one_period_decaying(hist, K * p, model):
                    continue  # a slowly alternating approach to a period-1 state
                p_found = p
                break
        long_p = 0 if p_found else _long_period(hist, K, model, amp_rtol, energy_rtol)
        growing = False if (p_found or long_p) else _growing(hist, model, amp_rtol)
        can_shoot = shooting and shots < config.SS_MAX_SHOTS
        # a multiple p > 1 may be a lightly damped transient whose free
        # frequency is commensurate with the forcing: first look for a
        # stable period-1 orbit by shooting (once per history)
        if (p_found > 1 or long_p) and can_shoot and not hist.shot_checked:
            hist.shot_checked = True
            shots += 1
            xs_, vs_, Ss_, ok, floq = _shoot(model, x.copy(), v.copy(), S.copy(), rdof, 0.1 * amp_rtol, counters)
            if ok and not (floq > 1.0 + config.SS_FLOQUET_TOL):
                x, v, S = xs_, vs_, np.ascontiguousarray(Ss_)
                hist = _History(np.concatenate([x, v]))
                p_found = 0
                continue
        if p_found:
            status = "periodic"
            detail = "shooting" if counters["shoot"] else "integration"
            break
        if long_p:
            status, detail = "not-settled", f"period-{long_p}"
            break
        if growing and not can_shoot:
            status, detail = "unbounded", "growing"
            break
        if counters["periods"] >= maxp:
            break
        if not can_shoot and _stalled(hist, model):
            break
        if can_shoot:
            est = _contraction(hist, model)
            need_shoot = False
            if est is not None:
                rho, dlast = est
                A = 0.5 * (hist.summ[-1][S_XMAX] - hist.summ[-1][S_XMIN])
                target = amp_rtol * _amplitude_scale(model, A)
                if growing:
                    need_shoot = True
                elif rho >= 1.0:
                    need_shoot = hist.size >= 2 * chunk
                elif dlast > target:
                    need_shoot = math.log(target / dlast) / math.log(rho) > config.SS_SHOOT_AFTER
            if need_shoot:
                shots += 1
                xs_, vs_, Ss_, ok, floq = _shoot(model, x.copy(), v.copy(), S.copy(), rdof, 0.1 * amp_rtol, counters)
                if ok and not (floq > 1.0 + config.SS_FLOQUET_TOL):
                    x, v, S = xs_, vs_, np.ascontiguousarray(Ss_)
                    hist = _History(np.concatenate([x, v]))

    if status is None:
        # did not settle within max_periods: say why if we can
        status = "not-settled"
        if hist.size >= config.SS_STALL_PERIODS and _stalled(hist, model):
            detail = "quasi-periodic-or-chaotic"
        else:
            detail = "slowly-converging"
    last = hist.summ[-1] if hist.size else None
    last_amp = 0.5 * (last[S_XMAX] - last[S_XMIN]) if last is not None else math.nan

    nan = math.nan
    vals = dict(amplitude_q=nan, amplitude_m=nan, offset_m=nan, max_abs_m=nan,
                energy_contact_J=nan, energy_viscous_J=nan, work_force_J=nan)  # fmt: skip
    loop = None
    if status == "periodic":
        p = p_found
        if keep_loop:
            summ, zend, st, done, smp = model.run_periods(x, v, S, p, rec=True, rdof=rdof)
            counters["periods"] += done
            counters["steps"] += int(summ[:, S_STEPS].sum())
            t, X, Vv, T, N, code = smp
            loop = Trajectory(t=t, x=X, v=Vv, T=T, N=N, code=code, final=Restart(x.copy(), v.copy(), S.copy()))
        else:
            summ = np.asarray(hist.summ[-p:])
        A = 0.5 * (summ[:, S_XMAX].max() - summ[:, S_XMIN].min())
        vals["amplitude_m"] = float(A)
        if system.contacts:
            law = system.contacts[0].law
            vals["amplitude_q"] = float(law.kt * A / law.fy) if law.fy > 0 else math.inf
        vals["offset_m"] = float(summ[:, S_XMEAN].mean())
        vals["max_abs_m"] = float(max(abs(summ[:, S_XMAX].max()), abs(summ[:, S_XMIN].min())))
        vals["energy_contact_J"] = float(summ[:, S_EC].mean())
        vals["energy_viscous_J"] = float(summ[:, S_EV].mean())
        vals["work_force_J"] = float(summ[:, S_W].mean())
    return SteadyState(
        status=status, detail=detail, period_multiple=int(p_found), gamma=gamma, omega=w,
        periods=int(math.ceil(counters["periods"])), steps=int(counters["steps"]),
        shooting_iterations=int(counters["shoot"]), floquet_max=float(floq),
        last_amplitude_m=float(last_amp), restart=Restart(x.copy(), v.copy(), S.copy()), loop=loop, **vals,
    )  # fmt: skip
