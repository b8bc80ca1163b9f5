"""Frequency-response and parameter branches by harmonic balance.

:func:`continue_hb` follows HB solutions of a :class:`~jointdyn.System` in
gamma = w / w0 or in another scalar parameter (see
:mod:`jointdyn.hb.parameters`) with the generic arc-length continuation of
:mod:`jointdyn.continuation`, marks the stability of
every point by Hill's method (:mod:`jointdyn.hb.stability`) and the folds,
and detects unbounded responses (MODEL.md section 6). :func:`frc_hb` is the
frequency-response front end returning an :class:`xarray.Dataset`.

Unbounded responses
-------------------
Without viscous damping the Coulomb-saturated oscillator has no steady
state at gamma = 1 when friction is too weak (Den Hartog: R/F < pi/4).
A branch point is declared ``unbounded`` when

* q = kt X / fy exceeds ``config.HB_UNBOUNDED_Q`` (hard bound, any system),
  or the corrector fails at the smallest step beyond
  ``config.HB_UNBOUNDED_FAIL_FRACTION`` of it; or
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

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .. import config
from ..continuation import (
    ContinuationOptions,
    ContinuationResult,
    ContinuationStatus,
    continuation,
    make_options,
    newton,
    turning_points,
)
from ..fourier import derivative_matrix
from ..laws import MACROSLIP, SEPARATION
from ..systems import System
from ._aft import INFO_ERROR, INFO_PASSES, INFO_PERIOD
from .parameters import GAMMA, parameter_named
from .problem import HBProblem, contact_of
from .stability import hill_growth, hill_stability

__all__ = ["HBBranch", "HBSolution", "continue_hb", "frc_hb", "branch_dataset", "harmonic_balance"]


@dataclass(frozen=True)
class HBBranch:
    """A harmonic-balance branch with stability and amplitudes (built by :func:`continue_hb`).

    Attributes
    ----------
    problem : HBProblem
    parameter : str
        Name of the continuation parameter.
    status : ContinuationStatus
        ``status.ok`` only for a complete branch.
    message : str
    lam : ndarray (points,)
        Parameter values.
    X : ndarray (points, n(2H+1))
        Harmonic coefficients, m.
    segment : ndarray of int (points,)
        0 for the branch from the start, 1 for the one continued back from
        the end after an unbounded stop.
    fold : ndarray of bool
    gap : ndarray of bool
        Point reached by a jump over a discontinuity of the contact force
        (do not join it to the previous point).
    counters : dict
    stable : ndarray of bool
        Hill's method.
    growth : ndarray
        max Re(s) / w of the selected Floquet exponents.
    passes, periodic_error, force_period : ndarray
        AFT periods marched, last-pass force difference (N), and the period
        of the marched force in forcing periods (1; 2 when the law's state
        alternates between two cycles, the mean of both is then used; 0 if
        it did not repeat within ``config.HB_MAX_PASSES``).
    response0 : ndarray (points, 3)
        (half peak-to-peak, mean, max |x|) of DOF 0 where the continuation
        monitor computed them (NaN elsewhere; see :meth:`response`).
    """

    problem: HBProblem
    parameter: str
    status: ContinuationStatus
    message: str
    lam: np.ndarray
    X: np.ndarray
    segment: np.ndarray
    fold: np.ndarray
    gap: np.ndarray
    counters: dict
    stable: np.ndarray
    growth: np.ndarray
    passes: np.ndarray
    periodic_error: np.ndarray
    force_period: np.ndarray
    response0: np.ndarray

    def gamma(self):
        """gamma = w / w0 per point."""
        if self.parameter == GAMMA.name:
            return self.lam.copy()
        return np.full(self.lam.size, self.problem.gamma_fixed)

    def response(self, dof: int = 0):
        """(amplitude_m, offset_m, max_abs_m) per point for DOF ``dof``."""
        out = self.response0.copy() if dof == 0 else np.full((self.lam.size, 3), np.nan)
        # rows computed by the monitor for the same X are kept; the others computed here
        for i in np.flatnonzero(np.isnan(out[:, 0])):
            out[i] = self.problem.amplitudes(self.X[i], dof)
        return out[:, 0], out[:, 1], out[:, 2]


def _make_branch(problem, status, message, lam, X, segment, fold, gap, counters, evaluations) -> HBBranch:
    """HBBranch of the continued points: AFT diagnostics and Hill stability of every point.

    ``evaluations`` maps a parameter value to ``(X, evaluation, amplitudes)``
    kept by the continuation monitor; they are reused where X is the very
    same, else the point is evaluated again.
    """
    n = lam.size
    passes = np.zeros(n, dtype=int)
    periodic_error = np.zeros(n)
    force_period = np.zeros(n, dtype=int)
    response0 = np.full((n, 3), np.nan)
    JXs = np.empty((n, problem.size, problem.size))
    for i in range(n):
        ev = evaluations.get(float(lam[i]))
        if ev is None or ev[0].tobytes() != X[i].tobytes():  # not kept for this very X
            ev = (X[i], problem.evaluate(X[i], lam[i]))
        elif len(ev) > 2:
            response0[i] = ev[2]
        ev = ev[1]
        JXs[i] = ev.JX
        passes[i] = int(ev.info[INFO_PASSES])
        periodic_error[i] = ev.info[INFO_ERROR]
        force_period[i] = int(ev.info[INFO_PERIOD])
    # Hill stability of every point (hill_stability's criterion), one compiled loop
    sysm = problem.system
    growth = hill_growth(JXs, sysm.M, sysm.C, np.array([problem.omega(v) for v in lam]), problem.H)
    return HBBranch(problem=problem, parameter=problem.parameter.name, status=status, message=message, lam=lam,
                    X=X, segment=segment, fold=fold, gap=gap, counters=counters,
                    stable=growth <= config.HB_STABILITY_RTOL, growth=growth, passes=passes,
                    periodic_error=periodic_error, force_period=force_period, response0=response0)


def _scales(problem: HBProblem, start: float):
    """(xs, fs, ps): units of the unknowns (fy/kt, m), of the residual (max(F1, fy), N) and of the parameter."""
    c = contact_of(problem.system)
    xs = c.law.fy / c.law.kt if c.law.fy > 0 else 1.0
    fs = max(problem.f1_ref, c.law.fy, 1e-300)
    return xs, fs, problem.parameter.scale(problem, start)


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
    D = derivative_matrix(problem.H)
    E = 0.0
    for T, b in zip(ev.T, problem.B):
        du = problem.E @ (D @ (Xm @ b))  # du/dtau at the samples
        E += float(np.sum(T * du)) * 2.0 * np.pi / problem.Ns
    X1 = problem.first_harmonic_amplitude(X, 0)
    F1 = float(np.max(np.abs(problem.parameter.forcing(problem, lam)[0])))
    R1 = E / (math.pi * X1) if X1 > 0 else math.inf
    if R1 < F1:
        return f"R1/F1 = {R1 / F1:.4g} < 1 (R/F = {math.pi / 4 * R1 / F1:.4g} < pi/4)"
    return None


class _Tracker:
    """Scaled residual and continuation monitor of one HB problem.

    The residual is that of the problem in scaled units (R / fs,
    JX xs / fs, Jp ps / fs); the monitor computes the amplitude of every
    accepted point, keeps its evaluation (for the stability and the
    response of the branch) and stops the branch on an unbounded response.
    """

    def __init__(self, problem: HBProblem, scales):
        self.problem = problem
        self.scales = scales
        law = contact_of(problem.system).law
        self.kt, self.fy = law.kt, law.fy
        self.last = None
        #: parameter value -> (X, evaluation, amplitudes of DOF 0) at accepted points
        self.evaluations = {}

    def residual(self, y, lam_s):
        xs, _, ps = self.scales
        ev = self.problem.evaluate(y * xs, lam_s * ps, self.scales)
        self.last = ev
        return ev.scaled

    def q(self, X, amps=None) -> float:
        """kt X / fy of DOF 0 (X the half peak-to-peak amplitude)."""
        if amps is None:
            amps = self.problem.amplitudes(X, 0)
        return self.kt * amps[0] / self.fy if self.fy > 0 else 0.0

    def monitor(self, y, lam_s):
        xs, _, ps = self.scales
        name = self.problem.parameter.name
        X = y * xs
        amps = self.problem.amplitudes(X, 0)
        q = self.q(X, amps)
        lam = lam_s * ps
        if self.last is not None:
            self.evaluations[float(lam)] = (X, self.last, amps)
        if not math.isfinite(q) or q > config.HB_UNBOUNDED_Q:
            return (ContinuationStatus.UNBOUNDED,
                    f"q = kt X / fy = {q:.4g} exceeds {config.HB_UNBOUNDED_Q:g} at {name} = {lam:.6g}")
        if self.last is not None:
            why = _saturation_test(self.problem, self.last, X, q, lam)
            if why is not None:
                return ContinuationStatus.UNBOUNDED, (
                    f"unbounded response (Den Hartog saturation: contact slips over the whole "
                    f"period, {why}) at {name} = {lam:.6g}, q = {q:.4g}")
        return None

    def relabel(self, res: ContinuationResult) -> ContinuationResult:
        """A corrector failure at a very large amplitude is an unbounded response."""
        if res.status is ContinuationStatus.FAILED and res.y.shape[0] > 0:
            q = self.q(res.y[-1] * self.scales[0])
            if q > config.HB_UNBOUNDED_FAIL_FRACTION * config.HB_UNBOUNDED_Q:
                return dataclasses.replace(
                    res, status=ContinuationStatus.UNBOUNDED,
                    message=f"Newton failed with q = {q:.4g} growing: unbounded response ({res.message})")
        return res


def _segment(tr: _Tracker, lam_a, lam_b, opt: ContinuationOptions, progress) -> ContinuationResult:
    """One continued segment from lam_a to lam_b (the start from the stuck linear solution)."""
    from tqdm.auto import tqdm

    problem = tr.problem
    xs, _, ps = tr.scales
    with tqdm(total=opt.max_points, desc=f"HB {problem.parameter.name}",
              disable=None if progress is None else not progress, leave=False) as bar:
        y0 = problem.linear_guess(lam_a) / xs
        if (problem.parameter is GAMMA
                and not newton(tr.residual, y0, lam_a / ps, opt, max_iter=config.HB_START_MAX_ITER)[1]):
            # start by a homotopy in the forcing amplitude at this gamma
            # when Newton from the stuck-contact solution fails
            sol = harmonic_balance(problem.system, lam_a, harmonics=problem.H, samples=problem.Ns, tol=opt.tol)
            if sol.converged:
                y0 = sol.X / xs
        return tr.relabel(continuation(tr.residual, y0, lam_a / ps, lam_b / ps, opt, monitor=tr.monitor,
                                       progress=bar))


def continue_hb(system: System, start: float, stop: float, *, parameter="gamma", gamma: float | None = None,
                harmonics: int = config.HB_HARMONICS, samples: int = config.HB_SAMPLES,
                options: ContinuationOptions | None = None, backward_after_unbounded: bool = True,
                progress: bool | None = None, **overrides) -> HBBranch:
    """Continue harmonic-balance solutions in a scalar parameter.

    Parameters
    ----------
    system : System
        Structure with contacts and forcing f sin(w t); normal loads
        N_c = n0 + n1 sin(w t + delta).
    start, stop : float
        Parameter range (start != stop); the branch starts at ``start``
        from the linear solution with stuck contacts.
    parameter : str or HBParameter
        ``gamma``, ``f1``, ``eta``, ``n0``, ``delta`` or a parameter object
        (:mod:`jointdyn.hb.parameters`, e.g. a ``SystemParameter`` for any
        value that builds the System).
    gamma : float, optional
        w / w0, required unless ``parameter == "gamma"``.
    harmonics : int
        Highest harmonic H (>= 1); harmonics 0..H are used.
    samples : int
        AFT time samples per period (>= 2H + 2).
    options : ContinuationOptions, optional
        Step control, in scaled units (unknowns in units of fy/kt of the
        first contact, parameter in its own scale, residual force /
        max(F1, fy)); keyword arguments override its fields (``ds``,
        ``ds_max``, ``max_points``, ``predictor``, ``tol``, ...).
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
    par = parameter_named(parameter)
    start = V.finite(par.name + " start", start)
    stop = V.finite(par.name + " stop", stop)
    if start == stop:
        raise ValueError(f"{par.name} range must not be empty (start == stop == {start!r})")
    par.check_range(start, stop)
    opt = make_options(options, overrides)
    V.positive_int("max_points", opt.max_points, 2)
    problem = HBProblem(system, harmonics=harmonics, samples=samples, parameter=par, gamma=gamma)
    tr = _Tracker(problem, _scales(problem, start))
    res = _segment(tr, start, stop, opt, progress)
    parts = [res]
    status, message = res.status, res.message
    left = opt.max_points - res.lam.size
    if res.status in (ContinuationStatus.UNBOUNDED, ContinuationStatus.FAILED) and backward_after_unbounded \
            and left >= 2:
        back = _segment(tr, stop, start, dataclasses.replace(opt, max_points=left), progress)
        parts.append(back)
        message += f"; continued back from {par.name} = {stop:.6g}: {back.status} ({back.message})"
        if res.lam.size == 0 and back.status is ContinuationStatus.COMPLETE:
            # no start at `start`, but the branch from `stop` covers the range
            status = ContinuationStatus.COMPLETE
            message = f"computed from {par.name} = {stop:.6g} back to {start:.6g} ({message})"
    return _join(tr, parts, status, message)


def _join(tr: _Tracker, parts, status, message) -> HBBranch:
    """The HBBranch of the continued segments (unscaled)."""
    problem = tr.problem
    xs, _, ps = tr.scales
    lam = np.concatenate([p.lam * ps for p in parts])
    X = np.concatenate([p.y * xs for p in parts]) if lam.size else np.empty((0, problem.size))
    seg = np.concatenate([np.full(p.lam.size, i) for i, p in enumerate(parts)]).astype(int)
    fold = np.concatenate([p.fold for p in parts]).astype(bool)
    gap = np.concatenate([p.gap for p in parts]).astype(bool)
    counters = {k: sum(p.counters.get(k, 0) for p in parts) for k in parts[0].counters}
    counters["segments"] = len(parts)
    if counters.get("jumps", 0):
        message += (f"; {counters['jumps']} jump(s) over discontinuities of the contact force "
                    "(points flagged 'gap')")
    return _make_branch(problem, status, message, lam, X, seg, fold, gap, counters, tr.evaluations)


def _turning_mask(branch):
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
        status=branch.status.value,
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


def frc_hb(system: System, gamma_start: float, gamma_stop: float, *, harmonics: int = config.HB_HARMONICS,
           samples: int = config.HB_SAMPLES, response_dof: int = 0, options: ContinuationOptions | None = None,
           progress: bool | None = None, **overrides):
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
    options : ContinuationOptions, optional
        Step control; keyword arguments override its fields (``ds``,
        ``ds_max``, ``max_points``, ``predictor``, ...).

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
                     parameter=GAMMA, harmonics=harmonics, samples=samples, options=options, progress=progress,
                     **overrides)
    return branch_dataset(br, response_dof)


@dataclass(frozen=True)
class HBSolution:
    """One harmonic-balance solution at fixed parameters (built by :func:`harmonic_balance`).

    Attributes
    ----------
    problem : HBProblem
    X : ndarray
        Harmonic coefficients (harmonic-major), m.
    converged : bool
    iterations : int
    residual_norm : float
        max |R| at X, N.
    amplitude_m, offset_m, max_abs_m : float
        Half peak-to-peak, mean and max |x| of ``response_dof``, m.
    stable : bool
        Hill's method.
    growth : float
        max Re(s) / w of the selected Floquet exponents.
    multipliers : ndarray complex
        Floquet multipliers exp(2 pi s / w) of the selected exponents.
    aft_info : ndarray
        AFT diagnostics (see ``jointdyn.hb._aft.INFO_*``).
    """

    problem: HBProblem
    X: np.ndarray
    converged: bool
    iterations: int
    residual_norm: float
    amplitude_m: float
    offset_m: float
    max_abs_m: float
    stable: bool
    growth: float
    multipliers: np.ndarray
    aft_info: np.ndarray


def _make_solution(problem: HBProblem, X, converged, iterations, response_dof) -> HBSolution:
    """HBSolution at X: residual, amplitudes of ``response_dof`` and Hill stability."""
    lam = problem.f1_ref
    ev = problem.evaluate(X, lam)
    amp, off, mx = problem.amplitudes(X, response_dof)
    stable, growth, mult = hill_stability(ev.JX, problem.system.M, problem.system.C, problem.omega(lam), problem.H)
    return HBSolution(problem=problem, X=X, converged=bool(converged), iterations=int(iterations),
                      residual_norm=float(np.max(np.abs(ev.R))), amplitude_m=amp, offset_m=off, max_abs_m=mx,
                      stable=stable, growth=growth, multipliers=mult, aft_info=ev.info)


def harmonic_balance(system: System, gamma: float, *, harmonics: int = config.HB_HARMONICS,
                     samples: int = config.HB_SAMPLES, guess=None, response_dof: int = 0,
                     tol: float = config.CONT_TOL, max_iter: int = config.HB_SOLVE_MAX_ITER) -> HBSolution:
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
        from ``config.HB_HOMOTOPY_START`` F1 to F1 at this gamma).
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
    gamma = V.positive("gamma", gamma)
    # the forcing amplitude as the (fixed) parameter: a problem at this gamma
    problem = HBProblem(system, harmonics=harmonics, samples=samples, parameter="f1", gamma=gamma)
    f1 = problem.f1_ref
    xs, fs, _ = _scales(problem, f1)

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
        br = continue_hb(system, config.HB_HOMOTOPY_START * f1, f1, parameter="f1", gamma=gamma,
                         harmonics=harmonics, samples=samples, tol=tol, backward_after_unbounded=False,
                         progress=False)
        if br.status is ContinuationStatus.COMPLETE and br.lam.size and br.lam[-1] == f1:
            y, ok, it = newton(residual, br.X[-1] / xs, 0.0, tol=tol, max_iter=max_iter)
    return _make_solution(problem, y * xs, ok, it, response_dof)
