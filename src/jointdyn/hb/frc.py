"""Frequency-response and parameter branches by harmonic balance.

:func:`continue_hb` follows HB solutions of a :class:`~jointdyn.System` in
gamma = w / w0 or in another scalar parameter (see
:data:`~jointdyn.hb.problem.PARAMETERS`) with the generic arc-length
continuation of :mod:`jointdyn.hb.continuation`, marks the stability of
every point by Hill's method (:mod:`jointdyn.hb.stability`) and the folds,
and detects unbounded responses (MODEL.md section 6). :func:`frc_hb` is the
frequency-response front end returning an :class:`xarray.Dataset`.

Unbounded responses
-------------------
Without viscous damping the Coulomb-saturated oscillator has no steady
state at gamma = 1 when friction is too weak (Den Hartog: R/F < pi/4).
A branch point is declared ``unbounded`` when

* q = kt X / fy exceeds ``config.HB_UNBOUNDED_Q`` (hard bound, any system),
  or the corrector fails at the smallest step beyond a tenth of it; or
* the describing-function saturation test holds: C = 0, q exceeds
  ``config.HB_SATURATION_Q``, every contact slips (macroslip or
  separation) over at least ``config.HB_SATURATION_SLIP_FRACTION`` of the
  period, and (single DOF) the friction force's equivalent first-harmonic
  amplitude R1 = E_fric / (pi X1) (E_fric the energy dissipated per cycle,
  X1 the first-harmonic amplitude; R1 = 4 mu N0 / pi for a Coulomb force
  at constant load) is below the forcing amplitude F1. Energy input
  pi F1 X1 then outgrows dissipation R1 pi X1 as the amplitude grows, so
  the branch rises without bound towards gamma = 1.

The branch computed up to that point is kept, and a second segment is
continued from ``stop`` backwards, so the Dataset shows both flanks with
``attrs["status"] == "unbounded"``. The same is done after a failure of
the corrector (status stays ``failed``, the message says where).
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V
from .. import config
from ..laws import MACROSLIP, SEPARATION
from ..systems import System
from .continuation import ContinuationResult, continuation
from .problem import PARAMETERS, HBProblem, contact_of
from .stability import hill_growth, hill_stability

__all__ = ["HBBranch", "HBSolution", "continue_hb", "frc_hb", "branch_dataset", "harmonic_balance"]


class HBBranch:
    """A harmonic-balance branch with stability and amplitudes.

    Attributes
    ----------
    problem : HBProblem
    parameter : str
    status, message : str
    lam : ndarray (points,)
        Parameter values.
    X : ndarray (points, n(2H+1))
        Harmonic coefficients, m.
    segment : ndarray of int (points,)
        0 for the branch from the start, 1 for the one continued back from
        the end after an unbounded stop.
    stable, fold : ndarray of bool
    gap : ndarray of bool
        Point reached by a jump over a discontinuity of the contact force
        (do not join it to the previous point).
    growth : ndarray
        max Re(s) / w of the selected Floquet exponents.
    passes, periodic_error, force_period : ndarray
        AFT periods marched, last-pass force difference (N), and the period
        of the marched force in forcing periods (1; 2 when the law's state
        alternates between two cycles, the mean of both is then used; 0 if
        it did not repeat within ``config.HB_MAX_PASSES``).
    counters : dict
    """

    def __init__(self, problem, parameter, status, message, lam, X, segment, fold, counters, gap=None,
                 evaluations=None):
        self.problem = problem
        self.parameter = parameter
        self.status = status
        self.message = message
        self.lam = lam
        self.X = X
        self.segment = segment
        self.fold = fold
        self.gap = np.zeros(lam.size, dtype=bool) if gap is None else gap
        self.counters = counters
        n = lam.size
        self.stable = np.zeros(n, dtype=bool)
        self.growth = np.full(n, np.nan)
        self.passes = np.zeros(n, dtype=int)
        self.periodic_error = np.zeros(n)
        self.force_period = np.zeros(n, dtype=int)
        sysm = problem.system
        evaluations = {} if evaluations is None else evaluations
        #: (half peak-to-peak, mean, max |x|) of DOF 0 per point where the
        #: continuation monitor computed them (NaN elsewhere)
        self._response0 = np.full((n, 3), np.nan)
        JXs = np.empty((n, problem.size, problem.size))
        for i in range(n):
            ev = evaluations.get(float(lam[i]))
            if ev is None or ev[0].tobytes() != X[i].tobytes():  # not kept for this very X
                ev = (X[i], problem.evaluate(X[i], lam[i]))
            elif len(ev) > 2:
                self._response0[i] = ev[2]
            ev = ev[1]
            JXs[i] = ev.JX
            self.passes[i] = int(ev.info[0])
            self.periodic_error[i] = ev.info[1]
            self.force_period[i] = int(ev.info[2])
        # Hill stability of every point (hill_stability's criterion), one compiled loop
        self.growth = hill_growth(JXs, sysm.M, sysm.C, np.array([problem.omega(v) for v in lam]), problem.H)
        self.stable = self.growth <= config.HB_STABILITY_RTOL

    def gamma(self):
        """gamma = w / w0 per point."""
        if self.parameter == "gamma":
            return self.lam.copy()
        return np.full(self.lam.size, self.problem.gamma_fixed)

    def response(self, dof: int = 0):
        """(amplitude_m, offset_m, max_abs_m) per point for DOF ``dof``."""
        out = self._response0.copy() if dof == 0 else np.full((self.lam.size, 3), np.nan)
        # rows computed by the monitor for the same X are kept; the others computed here
        for i in np.flatnonzero(np.isnan(out[:, 0])):
            out[i] = self.problem.amplitudes(self.X[i], dof)
        return out[:, 0], out[:, 1], out[:, 2]


def _scales(problem: HBProblem):
    c = contact_of(problem.system)
    xs = c.law.fy / c.law.kt if c.law.fy > 0 else 1.0
    fs = max(problem.f1_ref, c.law.fy, 1e-300)
    ls = {"gamma": 1.0, "f1": max(problem.f1_ref, 1.0), "eta": 1.0, "n0": max(c.n0, 1.0), "delta": 1.0}[problem.parameter]
    return xs, fs, ls


def _saturation_test(problem: HBProblem, ev, X, q, lam):
    """Describing-function saturation test (module docstring); None or reason."""
    if q < config.HB_SATURATION_Q or np.any(problem.system.C != 0.0) or problem.n != 1:
        return None
    for code in ev.code:
        slip = np.mean((code == MACROSLIP) | (code == SEPARATION))
        if slip < config.HB_SATURATION_SLIP_FRACTION:
            return None
    # energy dissipated by the contacts per cycle, E = sum_c oint T_c du_c
    Xm = X.reshape(problem.nh, problem.n)
    D = np.zeros((problem.nh, problem.nh))
    for k in range(1, problem.H + 1):
        D[2 * k - 1, 2 * k] = k
        D[2 * k, 2 * k - 1] = -k
    E = 0.0
    for T, b in zip(ev.T, problem.B):
        du = problem.E @ (D @ (Xm @ b))  # du/dtau at the samples
        E += float(np.sum(T * du)) * 2.0 * np.pi / problem.Ns
    X1 = problem.first_harmonic_amplitude(X, 0)
    F1 = float(np.max(np.abs(problem._split(lam)[1])))
    R1 = E / (math.pi * X1) if X1 > 0 else math.inf
    if R1 < F1:
        return f"R1/F1 = {R1 / F1:.4g} < 1 (R/F = {math.pi / 4 * R1 / F1:.4g} < pi/4)"
    return None


def continue_hb(
    system: System,
    start: float,
    stop: float,
    *,
    parameter: str = "gamma",
    gamma: float | None = None,
    harmonics: int = config.HB_HARMONICS,
    samples: int = config.HB_SAMPLES,
    ds: float | None = None,
    ds_max: float | None = None,
    max_points: int = config.HB_MAX_POINTS,
    predictor: str = "tangent",
    tol: float = config.HB_NEWTON_RTOL,
    backward_after_unbounded: bool = True,
    progress: bool | None = None,
) -> HBBranch:
    """Continue harmonic-balance solutions in a scalar parameter.

    Parameters
    ----------
    system : System
        Structure with contacts and forcing f sin(w t); normal loads
        N_c = n0 + n1 sin(w t + delta).
    start, stop : float
        Parameter range (start != stop); the branch starts at ``start``
        from the linear solution with stuck contacts.
    parameter : str
        ``gamma``, ``f1``, ``eta``, ``n0`` or ``delta`` (see
        :class:`~jointdyn.hb.problem.HBProblem`).
    gamma : float, optional
        w / w0, required unless ``parameter == "gamma"``.
    harmonics : int
        Highest harmonic H (>= 1); harmonics 0..H are used.
    samples : int
        AFT time samples per period (>= 2H + 2).
    ds, ds_max : float, optional
        Initial and largest arc-length step in scaled units (unknowns in
        units of fy/kt of the first contact, parameter in its own scale).
    max_points : int
        Bound on the number of branch points.
    predictor : {"tangent", "secant"}
    tol : float
        Newton tolerance on the scaled residual (force / max(F1, fy)).
    backward_after_unbounded : bool
        After an unbounded (or failed) stop, continue a second segment from
        ``stop`` backwards, so that both ends of the range are covered.
    progress : bool, optional
        Show a tqdm bar (None: only on a TTY).

    Returns
    -------
    HBBranch
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    contact_of(system)
    V.choice("parameter", parameter, PARAMETERS)
    start = V.finite(parameter + " start", start)
    stop = V.finite(parameter + " stop", stop)
    if start == stop:
        raise ValueError(f"{parameter} range must not be empty (start == stop == {start!r})")
    if parameter == "gamma":
        V.positive("gamma_start", start)
        V.positive("gamma_stop", stop)
    if parameter in ("n0", "f1"):
        V.positive(parameter + " start", start)
        V.positive(parameter + " stop", stop)
    if parameter == "eta":
        V.nonnegative("eta start", start)
        V.nonnegative("eta stop", stop)
    max_points = V.positive_int("max_points", max_points, 2)
    problem = HBProblem(system, harmonics=harmonics, samples=samples, parameter=parameter, gamma=gamma)
    xs, fs, ls = _scales(problem)
    ds = config.HB_DS_START if ds is None else V.positive("ds", ds)
    ds_max = config.HB_DS_MAX if ds_max is None else V.positive("ds_max", ds_max)
    law = contact_of(system).law
    cache = {}

    scales = (xs, fs, ls)

    def residual(y, lam_s):
        # scaled residual and Jacobians: R / fs, JX xs / fs, Jp ls / fs
        ev = problem.evaluate(y * xs, lam_s * ls, scales)
        cache["ev"] = ev
        return ev.scaled

    def qamp(X, amps=None):
        if amps is None:
            amps = problem.amplitudes(X, 0)
        return law.kt * amps[0] / law.fy if law.fy > 0 else 0.0

    evaluations = {}

    def monitor(y, lam_s):
        X = y * xs
        amps = problem.amplitudes(X, 0)
        q = qamp(X, amps)
        lam = lam_s * ls
        if "ev" in cache:
            # kept for the stability and the response of the accepted point
            evaluations[float(lam)] = (X, cache["ev"], amps)
        if not math.isfinite(q) or q > config.HB_UNBOUNDED_Q:
            return "unbounded", f"q = kt X / fy = {q:.4g} exceeds {config.HB_UNBOUNDED_Q:g} at {parameter} = {lam:.6g}"
        ev = cache.get("ev")
        if ev is not None:
            why = _saturation_test(problem, ev, X, q, lam)
            if why is not None:
                return "unbounded", (f"unbounded response (Den Hartog saturation: contact slips over the whole "
                                     f"period, {why}) at {parameter} = {lam:.6g}, q = {q:.4g}")
        return None

    from tqdm.auto import tqdm

    from .continuation import newton

    def run(lam_a, lam_b, npts):
        with tqdm(total=npts, desc=f"HB {parameter}", disable=None if progress is None else not progress,
                  leave=False) as bar:
            y0 = problem.linear_guess(lam_a) / xs
            if parameter == "gamma" and not newton(residual, y0, lam_a / ls, tol=tol, max_iter=30)[1]:
                # start by a homotopy in the forcing amplitude at this gamma
                # when Newton from the stuck-contact solution fails
                sol = harmonic_balance(system, lam_a, harmonics=harmonics, samples=samples, tol=tol)
                if sol.converged:
                    y0 = sol.X / xs
            return continuation(residual, y0, lam_a / ls, lam_b / ls, ds=ds, ds_max=ds_max, max_points=npts,
                                tol=tol, predictor=predictor, monitor=monitor, progress=bar)

    res = run(start, stop, max_points)
    res = _relabel_failure(res, xs, qamp)
    parts = [res]
    status, message = res.status, res.message
    if res.status in ("unbounded", "failed") and backward_after_unbounded and max_points - res.lam.size >= 2:
        back = _relabel_failure(run(stop, start, max_points - res.lam.size), xs, qamp)
        parts.append(back)
        message += f"; continued back from {parameter} = {stop:.6g}: {back.status} ({back.message})"
        if res.lam.size == 0 and back.status == "complete":
            # no start at `start`, but the branch from `stop` covers the range
            status = "complete"
            message = f"computed from {parameter} = {stop:.6g} back to {start:.6g} ({message})"
    lam = np.concatenate([p.lam * ls for p in parts])
    X = np.concatenate([p.y * xs for p in parts]) if lam.size else np.empty((0, problem.size))
    seg = np.concatenate([np.full(p.lam.size, i) for i, p in enumerate(parts)]).astype(int)
    fold = np.concatenate([p.fold for p in parts]).astype(bool)
    gap = np.concatenate([p.gap for p in parts]).astype(bool)
    counters = {k: sum(p.counters.get(k, 0) for p in parts) for k in parts[0].counters}
    counters["segments"] = len(parts)
    if counters.get("jumps", 0):
        message += (f"; {counters['jumps']} jump(s) over discontinuities of the contact force "
                    "(points flagged 'gap')")
    return HBBranch(problem, parameter, status, message, lam, X, seg, fold, counters, gap, evaluations)


def _relabel_failure(res: ContinuationResult, xs, qamp):
    """A corrector failure at a very large amplitude is an unbounded response."""
    if res.status == "failed" and res.y.shape[0] > 0:
        q = qamp(res.y[-1] * xs)
        if q > 0.1 * config.HB_UNBOUNDED_Q:
            res.status = "unbounded"
            res.message = f"Newton failed with q = {q:.4g} growing: unbounded response ({res.message})"
    return res


def _turning_mask(branch):
    from .continuation import turning_points

    m = np.zeros(branch.lam.size, dtype=bool)
    span = float(np.ptp(branch.lam)) if branch.lam.size else 0.0
    for sgm in np.unique(branch.segment):
        idx = np.flatnonzero(branch.segment == sgm)
        tp = turning_points(branch.lam[idx], branch.gap[idx], band=config.HB_TURNING_BAND * span)
        m[idx[tp]] = True
    return m


def branch_dataset(branch: HBBranch, response_dof: int = 0):
    """xarray Dataset of a branch (dim ``point``).

    Variables: ``gamma``, the parameter (if not gamma), ``amplitude_q``
    (kt X / fy of the first contact, X = half peak-to-peak of x(t) of
    ``response_dof``), ``amplitude_m`` (X, m), ``offset_m`` (mean, m),
    ``max_abs_m`` (m), ``stable``, ``fold`` (sign change of the parameter
    component of the Jacobian tangent: consistent with Hill's method, where
    a real Floquet multiplier crosses 1), ``turning`` (points where the
    parameter is extremal along the computed branch, the secant turning
    points, with a dead band of ``config.HB_TURNING_BAND`` of the range;
    on a piecewise-smooth branch they can differ from ``fold``),
    ``branch`` (segment index), ``gap``, ``growth``
    (max Re(s)/w of the Floquet exponents), ``aft_passes`` (periods
    marched), ``force_period`` (1; 2 when the law alternated between two
    cycles and their mean was used; 0 if the force did not repeat),
    ``harmonic_amplitude_m`` (dims point, harmonic: sqrt(a_k^2 + b_k^2),
    |a_0| for k = 0).
    """
    import xarray as xr

    p = branch.problem
    if not 0 <= response_dof < p.n:
        raise ValueError(f"response_dof must be in [0, {p.n - 1}], got {response_dof!r}")
    law = contact_of(p.system).law
    amp, off, mx = branch.response(response_dof)
    Xd = branch.X.reshape(-1, p.nh, p.n)[:, :, response_dof] if branch.X.size else np.empty((0, p.nh))
    harm = np.empty((Xd.shape[0], p.H + 1))
    harm[:, 0] = np.abs(Xd[:, 0])
    for k in range(1, p.H + 1):
        harm[:, k] = np.hypot(Xd[:, 2 * k - 1], Xd[:, 2 * k])
    turning = _turning_mask(branch)
    data = {
        "gamma": ("point", branch.gamma()),
        "amplitude_q": ("point", law.kt * amp / law.fy if law.fy > 0 else amp * np.nan),
        "amplitude_m": ("point", amp),
        "offset_m": ("point", off),
        "max_abs_m": ("point", mx),
        "stable": ("point", branch.stable),
        "fold": ("point", branch.fold),
        "turning": ("point", turning),
        "branch": ("point", branch.segment),
        "gap": ("point", branch.gap),
        "growth": ("point", branch.growth),
        "aft_passes": ("point", branch.passes),
        "force_period": ("point", branch.force_period),
        "harmonic_amplitude_m": (("point", "harmonic"), harm),
    }
    if branch.parameter != "gamma":
        data[branch.parameter] = ("point", branch.lam)
    attrs = {"gamma": {"long_name": "w / w0"}, "amplitude_q": {"long_name": "kt X / fy", "units": "1"},
             **{v: {"units": "m"} for v in ("amplitude_m", "offset_m", "max_abs_m", "harmonic_amplitude_m")}}
    # variables built with their attributes (no DataArray round trips afterwards)
    data = {k: xr.Variable(dims, np.asarray(v), attrs=attrs.get(k)) for k, (dims, v) in data.items()}
    ds = xr.Dataset(data, coords={"point": np.arange(branch.lam.size), "harmonic": np.arange(p.H + 1)})
    ds.attrs.update(
        status=branch.status,
        message=branch.message,
        method="hb",
        parameter=branch.parameter,
        harmonics=p.H,
        samples=p.Ns,
        response_dof=response_dof,
        points=int(branch.lam.size),
        folds=int(branch.fold.sum()),
        turning_points=int(turning.sum()),
        unstable_points=int((~branch.stable).sum()),
        max_aft_passes=int(branch.passes.max()) if branch.passes.size else 0,
        force_period_2_points=int((branch.force_period == 2).sum()),
        force_not_periodic_points=int((branch.force_period == 0).sum()),
        **{f"counter_{k}": int(v) for k, v in branch.counters.items()},
    )
    return ds


def frc_hb(
    system: System,
    gamma_start: float,
    gamma_stop: float,
    *,
    harmonics: int = config.HB_HARMONICS,
    samples: int = config.HB_SAMPLES,
    response_dof: int = 0,
    ds: float | None = None,
    ds_max: float | None = None,
    max_points: int = config.HB_MAX_POINTS,
    predictor: str = "tangent",
    progress: bool | None = None,
):
    """Frequency-response curve by harmonic balance and arc-length continuation.

    Harmonics 0..H of every DOF (normalised time tau = w t), contact forces
    by alternating frequency-time with ``samples`` per period, exact
    Jacobians by forward mode through the march of the contact laws,
    stability by Hill's method, folds from the tangent. See
    :func:`continue_hb` for the parameters.

    Parameters
    ----------
    system : System
    gamma_start, gamma_stop : float
        Range of gamma = w / w0 (> 0, distinct); the branch starts at
        ``gamma_start`` from the stuck-contact linear solution.
    harmonics : int
        H >= 1.
    samples : int
        >= 2H + 2.
    response_dof : int
        DOF whose response is reported.

    Returns
    -------
    xarray.Dataset
        Dim ``point``; variables ``gamma``, ``amplitude_q``,
        ``amplitude_m``, ``offset_m``, ``max_abs_m``, ``stable``, ``fold``
        (and ``turning``, ``branch``, ``gap``, ``growth``, ``aft_passes``,
        ``force_period``, ``harmonic_amplitude_m``; see
        :func:`branch_dataset`); attrs ``status`` (``complete`` |
        ``unbounded`` | ``failed`` | ``max-points``), ``message``,
        ``harmonics``, ``samples`` and the counters (``counter_*``).
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    V.positive_int("response_dof", response_dof, 0)
    if response_dof >= system.ndof:
        raise ValueError(f"response_dof must be in [0, {system.ndof - 1}], got {response_dof!r}")
    br = continue_hb(system, V.positive("gamma_start", gamma_start), V.positive("gamma_stop", gamma_stop),
                     parameter="gamma", harmonics=harmonics, samples=samples, ds=ds, ds_max=ds_max,
                     max_points=max_points, predictor=predictor, progress=progress)
    return branch_dataset(br, response_dof)


class HBSolution:
    """One harmonic-balance solution at fixed parameters.

    Attributes
    ----------
    converged : bool
    iterations : int
    X : ndarray
        Harmonic coefficients (harmonic-major), m.
    residual_norm : float
        max |R| at X, N.
    amplitude_m, offset_m, max_abs_m : float
        Half peak-to-peak, mean and max |x| of ``response_dof``, m.
    stable : bool
        Hill's method.
    problem : HBProblem
    """

    def __init__(self, problem, X, converged, iterations, response_dof):
        self.problem = problem
        self.X = X
        self.converged = bool(converged)
        self.iterations = int(iterations)
        p = problem
        lam = p.f1_ref
        ev = p.evaluate(X, lam)
        self.residual_norm = float(np.max(np.abs(ev.R)))
        self.amplitude_m, self.offset_m, self.max_abs_m = p.amplitudes(X, response_dof)
        self.stable, self.growth, self.multipliers = hill_stability(ev.JX, p.system.M, p.system.C, p.omega(lam), p.H)
        self.aft_info = ev.info


def harmonic_balance(system: System, gamma: float, *, harmonics: int = config.HB_HARMONICS,
                     samples: int = config.HB_SAMPLES, guess=None, response_dof: int = 0,
                     tol: float = config.HB_NEWTON_RTOL, max_iter: int = 50) -> HBSolution:
    """Solve the HB equations at one frequency by damped Newton.

    Parameters
    ----------
    system : System
    gamma : float
        w / w0 (> 0).
    harmonics, samples : int
        H >= 1 and AFT samples per period >= 2H + 2.
    guess : ndarray, optional
        Starting coefficients (default: the stuck-contact linear solution;
        if Newton fails from it, a continuation in the forcing amplitude
        from 1e-3 F1 to F1 at this gamma).
    response_dof : int
        DOF reported in the amplitudes.
    tol : float
        Tolerance on the residual scaled by max(F1, fy).
    max_iter : int
        Newton iterations.

    Returns
    -------
    HBSolution
        ``converged`` False when Newton failed (no exception).
    """
    from .continuation import newton

    gamma = V.positive("gamma", gamma)
    # problem with gamma as a fixed value: reuse the f1 parameterisation
    problem = HBProblem(system, harmonics=harmonics, samples=samples, parameter="f1", gamma=gamma)
    xs, fs, _ = _scales(problem)
    f1 = problem.f1_ref

    def residual(y, lam):
        ev = problem.evaluate(y * xs, f1)
        return ev.R / fs, ev.JX * (xs / fs), ev.Jp / fs

    y0 = (problem.linear_guess(f1) if guess is None else V.finite_array("guess", guess)) / xs
    if y0.size != problem.size:
        raise ValueError(f"guess must have length {problem.size}, got {y0.size}")
    y, ok, it = newton(residual, y0, 0.0, tol=tol, max_iter=max_iter)
    if not ok and guess is None and f1 > 0:
        # homotopy: continue in the forcing amplitude from a weak force,
        # where the stuck-contact linear solution is a good start
        br = continue_hb(system, 1e-3 * f1, f1, parameter="f1", gamma=gamma, harmonics=harmonics,
                         samples=samples, tol=tol, backward_after_unbounded=False, progress=False)
        if br.status == "complete" and br.lam.size and br.lam[-1] == f1:
            y, ok, it = newton(residual, br.X[-1] / xs, 0.0, tol=tol, max_iter=max_iter)
    sol = HBSolution(problem, y * xs, ok, it, response_dof)
    return sol
