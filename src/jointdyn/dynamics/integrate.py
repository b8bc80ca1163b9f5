"""Time integration of a :class:`~jointdyn.systems.System` (MODEL.md section 6).

Equation of motion (systems.py)::

    M x'' + C x' + K x = F(t) - sum_c B_c T_c(u_c, N_c(t)),   u_c = B_c . x,

with either harmonic loads ``F = f sin(w t)``, ``N_c = n0 + n1 sin(w t +
delta)`` (:func:`integrate`) or sampled ones (:func:`integrate_sampled`).
The scheme (explicit RK4 with trial/commit law evaluation, step boundaries
at separation/re-contact, steps split at velocity reversals) is described in
``_core.py`` and docs/time-integration.md.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .. import config
from ..laws.normal import HarmonicLoad
from ..systems import System
from ._core import N_SUMMARY, RUN_BLOWUP, RUN_OVERFLOW, compiled_runner, grid_loads, grid_sines

__all__ = ["Trajectory", "Restart", "integrate", "integrate_sampled"]


@dataclass(frozen=True)
class Restart:
    """State of a run at a forcing-period boundary (phase w t = 0 mod 2 pi).

    Opaque to users: pass it (or a :class:`SteadyState` holding it) as
    ``start`` to warm-start another run of the same system.

    Attributes
    ----------
    x, v : ndarray
        Displacements (m) and velocities (m/s), one per DOF.
    states : ndarray
        Committed law states, one row per contact.
    """

    x: np.ndarray
    v: np.ndarray
    states: np.ndarray


@dataclass(frozen=True)
class Trajectory:
    """Samples of a time integration (every accepted step end).

    Attributes
    ----------
    t : ndarray, shape (ns,)
        Time, s (the first sample is the initial state).
    x, v : ndarray, shape (ns, ndof)
        Displacements (m) and velocities (m/s).
    T : ndarray, shape (ns, ncontacts)
        Tangential contact forces, N.
    N : ndarray, shape (ns, ncontacts)
        Normal loads, N.
    code : ndarray of int8, shape (ns, ncontacts)
        Motion state per contact (STICK_SLIP, MACROSLIP, SEPARATION).
    final : Restart
        Final state (x, v, law states), usable as a start for a further run.
    status : str
        ``"ok"`` or ``"blow-up"`` (non-finite or astronomically large state).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    T: np.ndarray
    N: np.ndarray
    code: np.ndarray
    final: Restart
    status: str = "ok"


_STATIC: dict = {}


def _static_pack(system: System) -> dict:
    """The frequency-independent part of a :class:`_Model`, computed once per
    System object (a sweep builds one model per point)."""
    key = id(system)
    hit = _STATIC.get(key)
    if hit is not None and hit["_system"]() is system:
        return hit
    n = system.ndof
    cs = system.contacts
    d = {"_system": weakref.ref(system)}
    d["n"] = n
    d["nc"] = len(cs)
    d["M"] = np.ascontiguousarray(system.M, dtype=np.float64)
    d["Minv"] = np.ascontiguousarray(np.linalg.inv(system.M))
    d["K"] = np.ascontiguousarray(system.K, dtype=np.float64)
    d["C"] = np.ascontiguousarray(system.C, dtype=np.float64)
    d["fvec"] = np.ascontiguousarray(system.force, dtype=np.float64)
    d["cdof"] = np.array([c.dof for c in cs], dtype=np.int64)
    d["cdof2"] = np.array([c.dof2 for c in cs], dtype=np.int64)
    d["n0"] = np.array([c.n0 for c in cs], dtype=np.float64)
    d["n1"] = np.array([c.n1 for c in cs], dtype=np.float64)
    d["dlt"] = np.array([c.delta for c in cs], dtype=np.float64)
    if cs:
        plen = max(c.law.params.size for c in cs)
        P = np.zeros((len(cs), plen))
        for i, c in enumerate(cs):
            P[i, : c.law.params.size] = c.law.params
        d["P"] = P
        d["slen"] = max(c.law.state_size for c in cs)
        d["step"] = cs[0].law.step
        d["init"] = cs[0].law.init
    else:
        from ..laws import Jenkins

        dummy = Jenkins(kt=1.0, mu=0.0, n_ref=1.0)
        d["P"] = np.zeros((0, 5))
        d["slen"] = 1
        d["step"] = dummy.step
        d["init"] = dummy.init
    d["runner"] = compiled_runner(d["step"])
    # stiffest linear mode with every contact stuck: keeps RK4 accurate/stable
    Kst = d["K"].copy()
    for c in cs:
        B = np.zeros(n)
        B[c.dof] = 1.0
        if c.dof2 >= 0:
            B[c.dof2] -= 1.0
        Kst += c.law.kt * np.outer(B, B)
    d["K_stuck"] = np.ascontiguousarray(Kst)
    # contact selection rows (u_c = B[c] . x) and stuck stiffnesses
    Bsel = np.zeros((len(cs), n))
    for i, c in enumerate(cs):
        Bsel[i, c.dof] = 1.0
        if c.dof2 >= 0:
            Bsel[i, c.dof2] = -1.0
    d["B"] = Bsel
    d["kt"] = np.array([c.law.kt for c in cs], dtype=np.float64)
    from scipy.linalg import eigh

    lam = eigh(0.5 * (Kst + Kst.T), system.M, eigvals_only=True)
    d["w_max"] = math.sqrt(max(lam[-1], 0.0))
    d["w_min_stuck"] = math.sqrt(max(lam[0], 0.0))
    d["xlin"] = sum(c.law.fy / c.law.kt for c in cs)
    d["fmax"] = float(np.max(np.abs(d["fvec"])))
    d["kmin"] = max(d["w_min_stuck"] ** 2 * float(np.min(np.diag(system.M))), 1e-300)
    _STATIC[key] = d
    weakref.finalize(system, _STATIC.pop, key, None)
    return d


class _Model:
    """A System packed into flat arrays for the compiled runner at one frequency.

    The arrays are shared by every model of the same System object (see
    :func:`_static_pack`) and never written.
    """

    def __init__(self, system: System, w: float, steps_per_period: int, *, events: bool = True):
        if not isinstance(system, System):
            raise ValueError(f"system must be a System, got {type(system).__name__}")
        self.__dict__.update(_static_pack(system))
        self.system = system
        self.w = float(w)
        # events=False (for the convergence study only): no step boundaries
        # at separation/re-contact and no splits at velocity reversals
        self.events = bool(events)
        self.max_split = config.TI_MAX_SPLITS if events else 0
        J = int(steps_per_period)
        if self.w > 0:
            J = max(J, int(math.ceil(2 * math.pi * self.w_max / (self.w * config.TI_MAX_OMEGA_H))))
        self.J = J
        self._nobufs = _buffers(1, self.n, self.nc)
        self.set_cap(self.fmax)
        if self.w > 0:
            self._harmonic_grid()

    def set_cap(self, fs: float) -> None:
        """Caps of the blow-up guard (non-finite or absurdly large state) for force scale fs (N)."""
        xs = fs / self.kmin + self.xlin + 1e-12
        self._xcap0 = config.TI_BLOWUP_FACTOR * xs
        cap = np.empty(2 * self.n)
        cap[: self.n] = self._xcap0
        cap[self.n :] = self._xcap0 * max(self.w_max, self.w, 1.0)
        self.xcap = cap

    def cap(self, x, v) -> np.ndarray:
        """Blow-up caps, never below TI_BLOWUP_FACTOR times the starting state."""
        wv = max(self.w_max, self.w, 1.0)
        xs = float(np.max(np.abs(x))) + float(np.max(np.abs(v))) / wv
        if config.TI_BLOWUP_FACTOR * xs <= self._xcap0:
            return self.xcap  # the usual case: the start is far below the caps
        return np.maximum(self.xcap, config.TI_BLOWUP_FACTOR * np.concatenate([np.full(self.n, xs), np.full(self.n, xs * wv)]))

    # -- grid of one forcing period with the separation/re-contact instants --
    def _harmonic_grid(self) -> None:
        Tp = 2 * math.pi / self.w
        J = self.J
        t = np.arange(J + 1) * (Tp / J)  # np.linspace(0, Tp, J + 1), bit for bit, cheaper
        t[J] = Tp
        events = []  # (time, contact, rising)
        for ci, c in enumerate(self.system.contacts):
            if c.n1 > c.n0 and self.events:
                hl = HarmonicLoad(c.n0, c.n1, self.w, c.delta)
                for te in hl.zero_crossings(-1e-300, Tp):
                    te = float(te) % Tp
                    rising = math.cos(self.w * te + c.delta) > 0.0
                    events.append((te, ci, rising))
        tol = config.TI_EVENT_MERGE * Tp / J
        tg = t
        ev_at = {}
        for te, ci, rising in events:
            k = int(np.argmin(np.abs(tg - te)))
            if abs(tg[k] - te) <= tol:
                if k == 0 or k == tg.size - 1:
                    # an event at the period boundary: keep the boundary exact
                    te = tg[k]
                else:
                    tg[k] = te
                ev_at.setdefault(k, []).append((ci, rising))
            else:
                k = int(np.searchsorted(tg, te))
                tg = np.insert(tg, k, te)
                # re-key events recorded at later indices
                ev_at = {(kk + 1 if kk >= k else kk): v for kk, v in ev_at.items()}
                ev_at.setdefault(k, []).append((ci, rising))
        N = grid_loads(tg, self.w, self.n0, self.n1, self.dlt)
        for k, lst in ev_at.items():
            for ci, rising in lst:
                N[k, ci] = config.TI_RECONTACT_ALPHA * self.system.contacts[ci].n0 if rising else 0.0
                if k == 0:
                    N[tg.size - 1, ci] = N[0, ci]
                if k == tg.size - 1:
                    N[0, ci] = N[k, ci]
        self.tgrid = tg
        self.Ngrid = np.ascontiguousarray(N)
        self.sines = grid_sines(tg, self.w, 0.0, self.n0, self.n1, self.dlt)
        self.Fgrid = np.zeros((1, self.n))
        self.period = Tp

    def segment_grid(self, ta: float, tb: float):
        """Step grid and N table for ta < t <= tb (0 <= ta < tb <= ta + period), from the period grid."""
        Tp = self.period
        base = self.tgrid
        tt = np.concatenate([base[:-1], base + Tp])
        NN = np.concatenate([self.Ngrid[:-1], self.Ngrid], axis=0)
        eps = 1e-12 * Tp
        inside = (tt > ta + eps) & (tt < tb - eps)
        tg = np.concatenate([[ta], tt[inside], [tb]])
        Ng = np.empty((tg.size, self.nc))
        Ng[1:-1] = NN[inside]
        for ci, c in enumerate(self.system.contacts):
            Ng[0, ci] = c.n0 + c.n1 * math.sin(self.w * ta + c.delta)
            Ng[-1, ci] = c.n0 + c.n1 * math.sin(self.w * tb + c.delta)
        # an end point that is a grid point keeps its (event-snapped) value
        for idx, te in ((0, ta), (-1, tb)):
            k = np.flatnonzero(np.abs(tt - te) <= eps)
            if k.size:
                Ng[idx] = NN[k[0]]
        return np.ascontiguousarray(tg), np.ascontiguousarray(Ng)

    def section_time(self) -> float:
        """Poincare-section time in [0, period) where every contact is open, else 0.

        Mid-separation of the first separating contact; there the law states
        are reset, so (x, v) is the whole state of the period map.
        """
        for c in self.system.contacts:
            if c.n1 > c.n0:
                ts = ((1.5 * math.pi - c.delta) / self.w) % self.period
                if all(cc.n0 + cc.n1 * math.sin(self.w * ts + cc.delta) < 0.0 for cc in self.system.contacts):
                    return ts
                return 0.0
        return 0.0

    def run_grid(self, x, v, S, tg, Ng, nper, rdof=0, sines=None):
        """Run ``nper`` repetitions of a (partial or shifted) grid in place; (summary, zend, status, done).

        ``sines``: ``grid_sines`` of ``tg`` (computed here if not given; pass
        it when the same grid runs many times).
        """
        if sines is None:
            sines = self.sines_of(tg)
        summ = np.zeros((nper, N_SUMMARY))
        zend = np.zeros((nper, 2 * self.n))
        bufs = self._nobufs  # nothing is recorded
        _, status, done = self.runner(
            0, tg, Ng, self.Fgrid, nper, 0.0, self.w, self.fvec,
            self.n0, self.n1, self.dlt, self.Minv, self.K, self.C, self.cdof, self.cdof2,
            self.P, S, x, v, rdof, self.cap(x, v), self.max_split,
            False, *bufs, summ, zend, *sines,
        )  # fmt: skip
        return summ[:done], zend[:done], status, done

    def sines_of(self, tg):
        """``grid_sines`` of a step grid (cached for the period grid)."""
        if tg is self.tgrid:
            return self.sines
        return grid_sines(tg, self.w, 0.0, self.n0, self.n1, self.dlt)

    def initial_states(self, x: np.ndarray) -> np.ndarray:
        S = np.zeros((self.nc, self.slen))
        for i, c in enumerate(self.system.contacts):
            u = x[c.dof] - (x[c.dof2] if c.dof2 >= 0 else 0.0)
            # the grid value at t = 0 (event-snapped: a re-contact at t = 0
            # must start the virgin curve there)
            n_at0 = self.Ngrid[0, i] if hasattr(self, "Ngrid") else c.n0 + c.n1 * math.sin(c.delta)
            s = c.law.initial_state(float(u), float(n_at0))
            S[i, : s.size] = s
        return S

    def run_periods(self, x, v, S, nper, *, rec=False, rdof=0):
        """Run ``nper`` forcing periods in place; returns (summary, zend, status, done, samples)."""
        summ = np.zeros((nper, N_SUMMARY))
        zend = np.zeros((nper, 2 * self.n))
        cap = (nper * (self.J + 4 * self.nc + 8) + 1) if rec else 1
        if rec:
            x0, v0, S0 = x.copy(), v.copy(), S.copy()
        while True:
            bufs = _buffers(cap, self.n, self.nc) if rec else self._nobufs
            nrec, status, done = self.runner(
                0, self.tgrid, self.Ngrid, self.Fgrid, nper, 0.0, self.w, self.fvec,
                self.n0, self.n1, self.dlt, self.Minv, self.K, self.C, self.cdof, self.cdof2,
                self.P, S, x, v, rdof, self.cap(x, v), self.max_split,
                rec, *bufs, summ, zend, *self.sines,
            )  # fmt: skip
            if status != RUN_OVERFLOW:
                break
            cap *= 2
            x[:], v[:], S[:] = x0, v0, S0
        samples = tuple(b[:nrec] for b in bufs) if rec else None
        return summ[:done], zend[:done], status, done, samples


# mode 1 (sampled loads) takes no precomputed sines
_NO_SINES = (np.zeros(0), np.zeros(0), np.zeros((0, 0)))


def _buffers(cap, n, nc):
    return (
        np.zeros(cap),
        np.zeros((cap, n)),
        np.zeros((cap, n)),
        np.zeros((cap, nc)),
        np.zeros((cap, nc)),
        np.zeros((cap, nc), dtype=np.int8),
    )


def _omega(system: System, gamma) -> float:
    g = V.positive("gamma", gamma)
    w0 = system.w0
    if not w0 > 0:
        raise ValueError("system has no positive natural frequency w0 (gamma = w / w0 undefined)")
    return g * w0


def _start_vectors(model: _Model, x0, v0, states):
    n = model.n
    x = np.zeros(n) if x0 is None else V.finite_array("x0", np.atleast_1d(x0)).copy()
    v = np.zeros(n) if v0 is None else V.finite_array("v0", np.atleast_1d(v0)).copy()
    if x.shape != (n,):
        raise ValueError(f"x0 must have length {n}, got {x.shape[0]}")
    if v.shape != (n,):
        raise ValueError(f"v0 must have length {n}, got {v.shape[0]}")
    if states is None:
        S = model.initial_states(x)
    else:
        S = np.array(states, dtype=np.float64, ndmin=2)
        if S.shape != (model.nc, model.slen):
            raise ValueError(f"states must have shape {(model.nc, model.slen)}, got {S.shape}")
    return x, v, np.ascontiguousarray(S)


def integrate(
    system: System,
    gamma: float,
    *,
    periods: int = 1,
    steps_per_period: int | None = None,
    x0=None,
    v0=None,
    states=None,
    start: Restart | None = None,
) -> Trajectory:
    """Integrate the harmonically forced system over whole forcing periods.

    Solves M x'' + C x' + K x = f sin(w t) - sum_c B_c T_c(u_c, N_c(t)) with
    N_c(t) = n0 + n1 sin(w t + delta) (MODEL.md section 6) from t = 0.

    Parameters
    ----------
    system : System
        The structure, contacts and forcing amplitudes.
    gamma : float
        Frequency ratio w / w0 (> 0), w0 = ``system.w0``.
    periods : int
        Number of forcing periods (>= 1).
    steps_per_period : int, optional
        Base steps per forcing period (default ``config.TI_STEPS_PER_PERIOD``);
        raised automatically so that w_max h <= ``config.TI_MAX_OMEGA_H``
        for the stiffest stuck mode; events and reversals add steps.
    x0, v0 : array_like, optional
        Initial displacements (m) and velocities (m/s); default rest.
    states : array_like, optional
        Committed law states (one row per contact); default virgin at x0.
    start : Restart, optional
        Initial state from a previous run (overrides x0, v0, states).

    Returns
    -------
    Trajectory
        Samples at every accepted step end (grid points, separation and
        re-contact instants, velocity reversals of the contacts).
    """
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    spp = V.positive_int("steps_per_period", config.TI_STEPS_PER_PERIOD if steps_per_period is None else steps_per_period, 4)
    periods = V.positive_int("periods", periods)
    w = _omega(system, gamma)
    model = _Model(system, w, spp)
    if start is not None:
        x0, v0, states = start.x, start.v, start.states
    x, v, S = _start_vectors(model, x0, v0, states)
    _, _, status, _, smp = model.run_periods(x, v, S, periods, rec=True)
    t, X, Vv, T, N, code = smp
    return Trajectory(
        t=t, x=X, v=Vv, T=T, N=N, code=code,
        final=Restart(x.copy(), v.copy(), S.copy()),
        status="blow-up" if status == RUN_BLOWUP else "ok",
    )  # fmt: skip


def _as_samples(name, values, t, width):
    if callable(values):
        arr = np.array([np.atleast_1d(np.asarray(values(ti), dtype=float)) for ti in t])
    else:
        arr = np.asarray(values, dtype=float)
    if arr.ndim == 1 and width == 1:
        arr = arr[:, None]
    arr = V.finite_array(name, arr, 2)
    if arr.shape != (t.size, width):
        raise ValueError(f"{name} must have shape {(t.size, width)}, got {arr.shape}")
    return arr


def integrate_sampled(
    system: System,
    t,
    force,
    normal,
    *,
    x0=None,
    v0=None,
    states=None,
    start: Restart | None = None,
) -> Trajectory:
    """Integrate with forcing and normal loads given at sample times.

    F(t) and N_c(t) are piecewise linear between the samples; each sample
    interval is one RK4 step (use as many samples as accuracy needs), with
    an extra step boundary at every zero crossing of a normal load and steps
    split at velocity reversals of the contacts, as in :func:`integrate`.
    The system's own ``force``, ``n0``, ``n1`` and ``delta`` are ignored.

    Parameters
    ----------
    system : System
        Mass, damping, stiffness and contacts (laws and DOFs).
    t : array_like, shape (nt,)
        Strictly increasing sample times, s.
    force : array_like (nt, ndof) or callable
        Forcing per DOF at the samples, N; a callable ``F(t) -> (ndof,)`` is
        evaluated at the samples.
    normal : array_like (nt, ncontacts) or callable
        Normal loads at the samples, N; or a callable ``N(t) -> (ncontacts,)``.
    x0, v0, states, start
        As in :func:`integrate`.

    Returns
    -------
    Trajectory
    """
    t = V.increasing("t", V.finite_array("t", t))
    if t.size < 2:
        raise ValueError("t must have at least 2 samples")
    model = _Model(system, 0.0, 4)
    F = _as_samples("force", force, t, model.n)
    N = _as_samples("normal", normal, t, model.nc) if model.nc else np.zeros((t.size, 0))
    model.set_cap(float(np.max(np.abs(F))))
    # insert the zero crossings of the (piecewise-linear) normal loads
    tl, Fl, Nl = [t[0]], [F[0]], [N[0]]
    for i in range(t.size - 1):
        cross = []
        for c in range(model.nc):
            a, b = N[i, c], N[i + 1, c]
            if (a > 0) != (b > 0) and a != b:
                s = a / (a - b)
                if 0.0 < s < 1.0:
                    cross.append((s, c, b > 0))
        for s, c, rising in sorted(cross):
            ti = t[i] + s * (t[i + 1] - t[i])
            Fi = F[i] + s * (F[i + 1] - F[i])
            Ni = N[i] + s * (N[i + 1] - N[i])
            Ni[c] = config.TI_RECONTACT_ALPHA * abs(N[:, c]).max() if rising else 0.0
            tl.append(ti)
            Fl.append(Fi)
            Nl.append(Ni)
        tl.append(t[i + 1])
        Fl.append(F[i + 1])
        Nl.append(N[i + 1])
    tg = np.array(tl)
    Fg = np.ascontiguousarray(np.array(Fl).reshape(tg.size, model.n))
    Ng = np.ascontiguousarray(np.array(Nl).reshape(tg.size, model.nc))
    if start is not None:
        x0, v0, states = start.x, start.v, start.states
    x, v, S = _start_vectors(model, x0, v0, states)
    if states is None and start is None:
        for i, c in enumerate(system.contacts):
            u = x[c.dof] - (x[c.dof2] if c.dof2 >= 0 else 0.0)
            s = c.law.initial_state(float(u), float(Ng[0, i]))
            S[i, :] = 0.0
            S[i, : s.size] = s
    cap = tg.size * (1 + 2 * model.nc) + 8
    summ = np.zeros((1, N_SUMMARY))
    zend = np.zeros((1, 2 * model.n))
    x_in, v_in, S_in = x.copy(), v.copy(), S.copy()
    while True:
        bufs = _buffers(cap, model.n, model.nc)
        nrec, status, _ = model.runner(
            1, tg, Ng, Fg, 1, 0.0, 0.0, model.fvec, model.n0, model.n1, model.dlt,
            model.Minv, model.K, model.C, model.cdof, model.cdof2, model.P, S, x, v, 0,
            model.cap(x, v), config.TI_MAX_SPLITS, True, *bufs, summ, zend, *_NO_SINES,
        )  # fmt: skip
        if status != RUN_OVERFLOW:
            break
        cap *= 2
        x[:], v[:], S[:] = x_in, v_in, S_in
    tt, X, Vv, T, NN, code = (b[:nrec] for b in bufs)
    return Trajectory(
        t=tt, x=X, v=Vv, T=T, N=NN, code=code,
        final=Restart(x.copy(), v.copy(), S.copy()),
        status="blow-up" if status == RUN_BLOWUP else "ok",
    )  # fmt: skip
