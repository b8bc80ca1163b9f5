"""Frequency-response and parameter branches by harmonic balance.

:func:`continue_hb` follows HB solutions of a :class:`~jointdyn.System` in
gamma = w / w0 or in another scalar parameter (see
:mod:`jointdyn.hb.parameters`) with the generic arc-length continuation of
:mod:`jointdyn.continuation`, marks the stability of
every point by Hill's method (:mod:`jointdyn.hb.stability`) and the folds,
and detects unbounded responses (docs/model.md section 6). :func:`frc_hb` is the
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

After each jump of the continuation (over a discontinuity of the force,
or a stretch the corrector could not follow), a segment is continued back
from the point after the jump towards the point it left, so that a
resonance peak in that stretch is found (:attr:`HBPeak.at_stop` where the
curve could be followed only up to it).
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
    ParameterProgress,
    continuation,
    local_maxima,
    make_options,
    newton,
    refine_maximum,
    turning_points,
)
from ..fourier import derivative_matrix
from ..laws import MACROSLIP, SEPARATION
from ..status import Status
from ..systems import System
from ._aft import INFO_ERROR, INFO_PASSES, INFO_PERIOD
from .condense import make_problem
from .parameters import GAMMA, parameter_named
from .problem import HBProblem, contact_of

__all__ = ["AUTO", "DiscretisationCheck", "HBBranch", "HBPeak", "HBSolution", "PointStatus", "continue_hb",
           "frc_hb", "branch_dataset", "discretisation_attrs", "harmonic_balance"]


class PointStatus(Status):
    """How a point of a harmonic-balance branch joins the point before it (Dataset ``point_status``)."""

    START = "start", "first point of a segment: not joined to the point before it", True
    JOINED = "joined", "joined to the previous point along the branch", True
    CORNER = "corner", ("joined to the previous point past a sharp corner of the branch (found at fixed "
                        "parameter; the curve is continuous)"), True
    AFTER_JUMP = "after-jump", ("reached by a jump over a discontinuity of the contact force: not joined to the "
                                "previous point")
    STOPPED = "stopped", "last point of a segment that stopped short (the branch message says where and why)"


#: ``harmonics`` / ``samples`` value asking for the automatic choice (:func:`continue_hb`)
AUTO = config.HB_AUTO


@dataclass(frozen=True)
class DiscretisationCheck:
    """The convergence check of a branch's peaks in the harmonics and the samples.

    Every refined peak is solved again at its parameter value with 2H + 1
    harmonics (same samples, at least 2(2H + 1) + 2) and with 2 Ns samples
    (same harmonics), from the peak's own solution; the changes are
    relative to the peak's amplitude of the response DOF.

    Attributes
    ----------
    harmonics_auto, samples_auto : bool
        Which of the two were chosen automatically.
    levels : tuple of (int, int)
        (H, Ns) of every branch computed, the last one reported.
    check_harmonics, check_samples : int
        H and Ns of the check solves at the last level.
    harmonics_change, samples_change : float
        Largest change of a peak amplitude with ``check_harmonics``
        harmonics and with ``check_samples`` samples, relative to the
        highest peak of the branch (NaN without a peak; inf where a check
        solve did not converge).
    peaks : int
        Peaks checked.
    rtol : float
        Tolerance on the changes (``config.HB_AUTO_RTOL``).
    converged : bool
        Both changes within ``rtol`` (True without a peak).
    """

    harmonics_auto: bool
    samples_auto: bool
    levels: tuple
    check_harmonics: int
    check_samples: int
    harmonics_change: float
    samples_change: float
    peaks: int
    rtol: float
    converged: bool


@dataclass(frozen=True)
class HBPeak:
    """A maximum of the response amplitude along a branch, refined between its points.

    Attributes
    ----------
    lam : float
        Parameter value at the peak.
    gamma : float
        w / w0 at the peak.
    X : ndarray
        Harmonic coefficients there, m.
    amplitude_m : float
        Half peak-to-peak amplitude of the response DOF, m.
    amplitude_q : float
        kt X / fy of the first contact.
    segment : int
        Segment of the branch it lies on.
    refined : bool
        True when the refinement converged (else the best point found).
    at_stop : bool
        True when the highest point found is where a segment continued
        back over a jump stopped (the corrector could not follow the curve
        further, typically at a sharp fold of a non-smooth branch): not
        refined; the maximum of the branch is at least this amplitude and
        lies between this point and the point the jump left.
    """

    lam: float
    gamma: float
    X: np.ndarray
    amplitude_m: float
    amplitude_q: float
    segment: int
    refined: bool
    at_stop: bool = False


@dataclass(frozen=True)
class HBBranch:
    """A harmonic-balance branch with stability and amplitudes (built by :func:`continue_hb`).

    Attributes
    ----------
    problem : HBProblem
    parameter : str
        Name of the continuation parameter.
    status : ContinuationStatus
        ``complete`` only when the computed points cover the requested
        range; ``unbounded`` when the response grows without bound inside
        it (both flanks computed); otherwise what stopped it (``failed``,
        ``turned-back``, ``max-points``, ``stopped``).
    message : str
        Where and why each segment stopped, and the parts of the range
        not computed.
    lam : ndarray (points,)
        Parameter values.
    X : ndarray (points, n(2H+1))
        Harmonic coefficients, m.
    segment : ndarray of int (points,)
        0 for the branch from the start, 1 for the one continued back from
        the end after a stop short of it; then one per jump, continued back
        from the point after the jump towards the point it left (the
        stretch the jump passed over, where a peak may lie).
    fold : ndarray of bool
        Turning points in the parameter (see :func:`branch_dataset`).
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
        (half peak-to-peak, mean, max |x|) of the response DOF where the
        continuation monitor computed them (NaN elsewhere; see :meth:`response`).
    point_status : ndarray of PointStatus (points,)
        How each point joins the one before it.
    peaks : tuple of HBPeak
        Maxima of the response amplitude, refined between the points.
    uncovered : tuple of (float, float)
        Parts of the requested range without a computed point (empty for a
        complete branch; for an unbounded one, where the response has no
        bound).
    response_dof : int
        DOF of ``response0``, of the peaks and of the step control.
    discretisation : DiscretisationCheck or None
        The automatic choice of harmonics and samples and the convergence
        check of the peaks (None when both were given).
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
    point_status: np.ndarray
    peaks: tuple
    uncovered: tuple
    response_dof: int
    discretisation: DiscretisationCheck | None = None

    def gamma(self):
        """gamma = w / w0 per point."""
        if self.parameter == GAMMA.name:
            return self.lam.copy()
        return np.full(self.lam.size, self.problem.gamma_fixed)

    def response(self, dof: int | None = None):
        """(amplitude_m, offset_m, max_abs_m) per point for DOF ``dof`` (default: the response DOF)."""
        dof = self.response_dof if dof is None else dof
        out = self.response0.copy() if dof == self.response_dof else np.full((self.lam.size, 3), np.nan)
        # rows computed by the monitor for the same X are kept; the others computed here
        for i in np.flatnonzero(np.isnan(out[:, 0])):
            out[i] = self.problem.amplitudes(self.X[i], dof, self.lam[i])
        return out[:, 0], out[:, 1], out[:, 2]


@dataclass(frozen=True)
class _Parts:
    """The continued segments of a branch with what the HBBranch takes from them (unscaled)."""

    lam: np.ndarray
    X: np.ndarray
    segment: np.ndarray
    fold: np.ndarray
    gap: np.ndarray
    point_status: np.ndarray
    counters: dict


@dataclass(frozen=True)
class _Draft:
    """A continued branch before the per-point AFT diagnostics and Hill stability of its HBBranch
    (:func:`_make_branch`): what the automatic choice of harmonics and samples reads of a branch,
    so that the branches it discards are never analysed."""

    tr: _Tracker
    status: ContinuationStatus
    message: str
    parts: _Parts
    peaks: tuple
    uncovered: tuple

    @property
    def problem(self) -> HBProblem:
        return self.tr.problem

    def branch(self) -> HBBranch:
        """The HBBranch (AFT diagnostics and Hill stability of every point)."""
        return _make_branch(self.tr, self.status, self.message, self.parts, self.peaks, self.uncovered)


def _make_branch(tr, status, message, parts: _Parts, peaks, uncovered) -> HBBranch:
    """HBBranch of the continued points: AFT diagnostics and Hill stability of every point.

    The evaluations kept by the continuation monitor (``tr.evaluations``:
    parameter value -> (X, evaluation, amplitudes)) are reused where X is
    the very same, else the point is evaluated again.
    """
    problem = tr.problem
    lam, X = parts.lam, parts.X
    n = lam.size
    passes = np.zeros(n, dtype=int)
    periodic_error = np.zeros(n)
    force_period = np.zeros(n, dtype=int)
    response0 = np.full((n, 3), np.nan)
    JXs = np.empty((n, problem.size, problem.size))
    for i in range(n):
        ev = tr.evaluations.get(float(lam[i]))
        if ev is None or ev[0].tobytes() != X[i].tobytes():  # not kept for this very X
            ev = (X[i], problem.evaluate(X[i], lam[i]))
        elif len(ev) > 2:
            response0[i] = ev[2]
        ev = ev[1]
        JXs[i] = ev.JX
        passes[i] = int(ev.info[INFO_PASSES])
        periodic_error[i] = ev.info[INFO_ERROR]
        force_period[i] = int(ev.info[INFO_PERIOD])
    # Hill stability of every point (hill_stability's criterion; NaN where a condensed problem does not compute it)
    growth = problem.hill_growth(JXs, np.array([problem.omega(v) for v in lam]))
    stable, checked = _confirmed_stability(problem, X, lam, growth)
    counters = {**parts.counters, "monodromy_checks": checked}
    # folds need the stability on both sides; without it (a large condensed problem) the turning points stand
    fold = _saddle_nodes(parts.fold, stable, parts.segment) if np.all(np.isfinite(growth)) else parts.fold
    return HBBranch(problem=problem, parameter=problem.parameter.name, status=status, message=message, lam=lam,
                    X=X, segment=parts.segment, fold=fold, gap=parts.gap, counters=counters,
                    stable=stable, growth=growth, passes=passes,
                    periodic_error=periodic_error, force_period=force_period, response0=response0,
                    point_status=parts.point_status, peaks=tuple(peaks), uncovered=tuple(uncovered),
                    response_dof=tr.dof)


def _saddle_nodes(turning, stable, segment):
    """The turning points that can be folds: an unstable point next to them along the branch.

    At a fold of a smooth branch a real Floquet multiplier crosses +1, so
    the number of unstable multipliers changes by one there and one side of
    it is unstable. A turning point is kept when the stretch to the
    neighbouring turning point on either side (or, without one, the
    ``config.HB_FOLD_WINDOW`` points on that side) holds an unstable point;
    on a piecewise-smooth branch the change of stability can lie a few
    points before the extreme of the parameter. Turning points with stable
    points all around are zigzags of the branch at corners or jumps of a
    closed-form contact force, not folds: a sweep does not jump there.
    """
    out = np.zeros_like(turning)
    k = config.HB_FOLD_WINDOW
    for sgm in np.unique(segment):
        idx = np.flatnonzero(segment == sgm)
        tp = np.flatnonzero(turning[idx])
        for j, i in enumerate(tp):
            lo = tp[j - 1] if j > 0 else max(i - k, 0)
            hi = tp[j + 1] if j + 1 < tp.size else min(i + k, idx.size - 1)
            out[idx[i]] = not stable[idx[lo:hi + 1]].all()
    return out


def _confirmed_stability(problem: HBProblem, X, lam, growth):
    """(stable, number of monodromy checks): Hill's criterion, with marginal growth decided by the monodromy.

    Hill's method truncated to H harmonics is only approximate where the
    contact force has a corner (the onset of slip of a Jenkins element on
    an otherwise undamped oscillator gives Re(s)/w of a few 1e-6 at
    points whose period map is contracting). A growth between
    ``config.HB_STABILITY_RTOL`` and ``config.HB_STABILITY_CONFIRM`` is
    therefore decided by the Floquet multipliers of the time-domain period
    map (:func:`~jointdyn.hb.monodromy.monodromy_multipliers`): unstable
    when one lies outside the unit circle by more than
    ``2 pi config.HB_STABILITY_RTOL``.
    """
    from .monodromy import monodromy_multipliers

    stable = growth <= config.HB_STABILITY_RTOL
    marginal = np.flatnonzero(~stable & (growth < config.HB_STABILITY_CONFIRM))
    for i in marginal:
        mu = np.max(np.abs(monodromy_multipliers(problem, X[i], lam[i])))
        stable[i] = mu <= 1.0 + 2.0 * math.pi * config.HB_STABILITY_RTOL
    return stable, int(marginal.size)


def _scales(problem: HBProblem, start: float):
    """(xs, fs, ps): units of the unknowns (fy/kt, m), of the residual (max(F1, fy), N) and of the parameter."""
    c = contact_of(problem.system)
    xs = c.law.fy / c.law.kt if c.law.fy > 0 else 1.0
    fs = max(problem.f1_ref, c.law.fy, 1e-300)
    return xs, fs, problem.parameter.scale(problem, start)


def _saturation_test(problem: HBProblem, ev, X, q, lam):
    """Describing-function saturation test (module docstring); None or reason."""
    if q < config.HB_SATURATION_Q or np.any(problem.system.C != 0.0) or problem.system.ndof != 1:
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
    """Scaled residual, observable and continuation monitor of one HB problem.

    The residual is that of the problem in scaled units (R / fs,
    JX xs / fs, Jp ps / fs); the step control's observable is the
    logarithm of the norm of the response DOF's harmonics (the chords of the
    plotted curve stay within ``chord_tol`` of it, relative in amplitude),
    peaks and folds use log q itself; the monitor computes the
    amplitude of every accepted point, keeps its evaluation (for the
    stability and the response of the branch) and stops the branch on an
    unbounded response.
    """

    def __init__(self, problem: HBProblem, scales, dof: int):
        self.problem = problem
        self.scales = scales
        self.dof = dof
        law = contact_of(problem.system).law
        self.kt, self.fy = law.kt, law.fy
        self.last = None
        #: parameter value -> (X, evaluation, amplitudes of the response DOF) at accepted points
        self.evaluations = {}
        #: the amplitudes of the last few unknowns asked for (observable and monitor share them)
        self._amps = {}
        #: the amplitudes of every accepted point (the branch's observable asks for them again)
        self._accepted_amps = {}

    def residual(self, y, lam_s):
        xs, _, ps = self.scales
        ev = self.problem.evaluate(y * xs, lam_s * ps, self.scales)
        self.last = ev
        return ev.scaled

    def amplitudes(self, y):
        """(half peak-to-peak, mean, max |x|) of the response DOF at scaled unknowns y, m."""
        key = y.tobytes()
        hit = self._amps.get(key) or self._accepted_amps.get(key)
        if hit is None:
            if len(self._amps) >= _AMPLITUDE_CACHE:
                self._amps.clear()
            hit = self._amps[key] = self.problem.amplitudes(y * self.scales[0], self.dof)
        return hit

    def q(self, amp) -> float:
        """kt X / fy (X the half peak-to-peak amplitude, m)."""
        return self.kt * amp / self.fy if self.fy > 0 else amp / self.scales[0]

    def observe(self, y, lam_s) -> float:
        """log q of the response DOF (NaN at zero amplitude)."""
        q = self.q(self.amplitudes(y)[0])
        return math.log(q) if q > 0 else math.nan

    def observe_step(self, y, lam_s) -> float:
        """log of the norm of the response DOF's harmonics 1..H (scaled units; NaN at zero).

        The step control's observable: it follows log q within a constant
        where the response is near-harmonic and costs a few flops, where q
        (the half peak-to-peak of a finely sampled period) costs a
        sampling per call.
        """
        p = self.problem
        h = y.reshape(p.nh, p.n)[1:, p.dof_index(self.dof)]
        a = math.sqrt(float(h @ h))
        return math.log(a) if a > 0 else math.nan

    def monitor(self, y, lam_s):
        xs, _, ps = self.scales
        name = self.problem.parameter.name
        X = y * xs
        amps = self._accepted_amps[y.tobytes()] = self.amplitudes(y)
        q = self.q(amps[0])
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
            q = self.q(self.amplitudes(res.y[-1])[0])
            if q > config.HB_UNBOUNDED_FAIL_FRACTION * config.HB_UNBOUNDED_Q:
                return dataclasses.replace(
                    res, status=ContinuationStatus.UNBOUNDED,
                    message=f"Newton failed with q = {q:.4g} growing: unbounded response ({res.message})")
        return res


#: amplitudes kept by a tracker before its cache is cleared (a step asks for a few)
_AMPLITUDE_CACHE = 8


def _bar(start: float, stop: float, desc: str, progress, name: str, scale: float):
    """A bar over the range [start, stop] of the (scaled) parameter (:class:`ParameterProgress`, shown on a
    TTY when ``progress`` is None), or a null context without one when it is False (tqdm is not even
    imported: it takes a noticeable part of a short command's time)."""
    if progress is False:
        import contextlib

        return contextlib.nullcontext(None)
    return ParameterProgress(start, stop, desc, progress, name=name, scale=scale)


def _segment(tr: _Tracker, lam_a, lam_b, opt: ContinuationOptions, progress, monitor=None) -> ContinuationResult:
    """One continued segment from lam_a to lam_b (the start from the stuck linear solution); ``monitor``
    defaults to the tracker's."""
    problem = tr.problem
    xs, _, ps = tr.scales
    with _bar(lam_a / ps, lam_b / ps, f"HB {problem.parameter.name}", progress, problem.parameter.name, ps) as bar:
        y0 = problem.linear_guess(lam_a) / xs
        if (problem.parameter is GAMMA
                and not newton(tr.residual, y0, lam_a / ps, opt, max_iter=config.HB_START_MAX_ITER)[1]):
            # start by a homotopy in the forcing amplitude at this gamma
            # when Newton from the stuck-contact solution fails
            sol = harmonic_balance(problem.system, lam_a, harmonics=problem.H, samples=problem.Ns, tol=opt.tol,
                                   condense=problem.condensed)
            if sol.converged:
                y0 = sol.X / xs
        return tr.relabel(continuation(tr.residual, y0, lam_a / ps, lam_b / ps, opt,
                                       monitor=tr.monitor if monitor is None else monitor,
                                       progress=bar, observe=tr.observe_step, lam_name=problem.parameter.name))


def _gap_fills(tr: _Tracker, parts, span: float, opt: ContinuationOptions, progress) -> list:
    """Segments continued back from the point after each jump of ``parts`` towards the point it left.

    A jump passes over a stretch of the branch the corrector could not
    follow (a fold or a sharp rise at a corner of the contact force, where
    a resonance peak may lie). Continued from the other side, the curve is
    usually followable up to the same obstacle, so the stretch between is
    traced and its peak found. Only a jump that may hide a peak is filled
    (:func:`_may_hide_a_peak`). Each fill is bounded by the parameter range
    of its jump and one largest parameter step beyond the point the jump
    left (so that a fold just past that point is passed), and ends once
    past that point below its amplitude (:class:`_FillMonitor`); its own
    jumps are as long as those of the branch (range ``span``, scaled), not
    scaled down to its short range. Its status (often a stall at the
    obstacle) is named in the branch's message but does not decide the
    branch's status.

    Returns a list of ``(fill, y_left)``: the segment and the scaled
    unknowns of the point the jump left.
    """
    name = tr.problem.parameter.name
    fills = []
    for p in parts:
        for i in np.flatnonzero(p.gap):
            if not _may_hide_a_peak(tr, p, i):
                continue
            end = p.lam[i - 1] + math.copysign(min(opt.max_dlam, span), p.lam[i - 1] - p.lam[i])
            reach = abs(p.lam[i] - end)
            fopt = dataclasses.replace(opt, jump_fractions=tuple(f * span / reach for f in opt.jump_fractions))
            with _bar(p.lam[i], end, f"HB {name} (gap)", progress, name, tr.scales[2]) as bar:
                fill = tr.relabel(continuation(tr.residual, p.y[i], p.lam[i], end, fopt,
                                               monitor=_FillMonitor(tr, p.lam[i - 1], p.lam[i], p.y[i - 1]),
                                               progress=bar, observe=tr.observe_step, lam_name=name))
            fills.append((fill, p.y[i - 1]))
    return fills


def continue_hb(system: System, start: float, stop: float, *, parameter="gamma", gamma: float | None = None,
                harmonics: int | str = AUTO, samples: int | str = AUTO,
                max_step: float | None = None, response_dof: int | None = None,
                options: ContinuationOptions | None = None, backward_after_unbounded: bool = True,
                progress: bool | None = None, condense: bool | None = None, **overrides) -> HBBranch:
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
    harmonics : int or "auto"
        Highest harmonic H (>= 1); harmonics 0..H are used. ``"auto"``
        (default): start at ``config.HB_HARMONICS``; every refined peak is
        solved again with 2H + 1 harmonics and, where its amplitude changes
        by more than ``config.HB_AUTO_RTOL``, the branch is computed again
        with more (up to ``config.HB_AUTO_MAX_HARMONICS``).
    samples : int or "auto"
        AFT time samples per period (>= 2H + 2). ``"auto"`` (default):
        start at ``config.HB_SAMPLES`` and double the same way, checked
        with 2 Ns samples (up to ``config.HB_AUTO_MAX_SAMPLES``). The
        levels used and the check are in ``HBBranch.discretisation``; a
        converged branch costs two extra solves per peak.
    max_step : float, optional
        Largest change of the parameter between consecutive points (in its
        own unit, e.g. a gamma grid spacing); default
        ``config.HB_MAX_GAMMA_STEP`` when the parameter is gamma, none
        beyond the chord bound otherwise.
    response_dof : int, optional
        DOF whose amplitude the step control follows and the peaks report
        (default ``system.response_dof``).
    options : ContinuationOptions, optional
        Step control, in scaled units (unknowns in units of fy/kt of the
        first contact, parameter in its own scale, residual force /
        max(F1, fy)); keyword arguments override its fields (``ds``,
        ``ds_max``, ``max_points`` (per segment), ``chord_tol``, ...). ``chord_tol``
        bounds the distance between the straight lines joining the points
        and the curve in the plane (parameter, log q): 0.005 is half a
        percent of the amplitude.
    backward_after_unbounded : bool
        After a stop short of ``stop`` (unbounded, failed, turned back),
        continue a second segment from ``stop`` backwards, so that both
        ends of the range are covered.
    progress : bool, optional
        Show a tqdm bar (None: only on a TTY).
    condense : bool, optional
        Condense the problem exactly onto the contact DOFs
        (:mod:`jointdyn.hb.condense`); None chooses by size
        (:func:`~jointdyn.hb.condense.use_condensed`).

    Returns
    -------
    HBBranch
        With its status (``complete`` only when the range is covered),
        per-point status, refined peaks and uncovered parts of the range.
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
    dof = system.response_dof if response_dof is None else V.positive_int("response_dof", response_dof, 0)
    if dof >= system.ndof:
        raise ValueError(f"response_dof must be in [0, {system.ndof - 1}], got {dof!r}")
    opt = make_options(options, overrides)
    V.positive_int("max_points", opt.max_points, 2)
    if opt.start_extrapolation is None and all(c.law.smooth_force for c in system.contacts):
        # every force smooth at the onset of slip: the corrector starts from the branch's extrapolation
        opt = dataclasses.replace(opt, start_extrapolation=config.CONT_START_EXTRAPOLATION)
    if max_step is None and par is GAMMA:
        max_step = config.HB_MAX_GAMMA_STEP
    if max_step is not None:
        V.positive("max_step", max_step)
    level, auto = _first_level(harmonics, samples)
    req = _Request(system=system, start=start, stop=stop, parameter=par, gamma=gamma, max_step=max_step, dof=dof,
                   options=opt, backward=backward_after_unbounded, progress=progress, condense=condense)
    return _adaptive_branch(req, level, auto)


@dataclass(frozen=True)
class _Request:
    """What a branch is asked for, apart from its discretisation (validated by :func:`continue_hb`)."""

    system: System
    start: float
    stop: float
    parameter: object
    gamma: float | None
    max_step: float | None
    dof: int
    options: ContinuationOptions
    backward: bool
    progress: bool | None
    condense: bool | None


def _fixed_branch(req: _Request, level, auto=(False, False), watch: bool = False):
    """The branch with H harmonics and Ns samples, ``level = (H, Ns)``: a :class:`_Draft`, or, with
    ``watch``, a :class:`_Refine` where a peak asked for a finer level while the branch was continued
    (``auto``: which of (harmonics, samples) may change; :class:`_PeakWatch`)."""
    problem = make_problem(req.system, condense=req.condense, response_dofs=(req.dof,), harmonics=level[0],
                           samples=level[1], parameter=req.parameter, gamma=req.gamma)
    tr = _Tracker(problem, _scales(problem, req.start), req.dof)
    opt = req.options
    if req.max_step is not None:
        opt = dataclasses.replace(opt, max_dlam=req.max_step / tr.scales[2])
    watch = _PeakWatch(tr, req, level, auto, opt) if watch and any(auto) else None
    res = _segment(tr, req.start, req.stop, opt, req.progress, watch)
    if watch is not None and watch.target is not None:
        return watch.target
    parts = [res]
    # the segment back from the end has a bound of its own: the first one may have spent its points
    # on a flank that grows without bound
    if res.status in _GO_BACK and req.backward:
        if watch is not None:
            watch.restart()
        back = _segment(tr, req.stop, req.start, opt, req.progress, watch)
        if watch is not None and watch.target is not None:
            return watch.target
        parts.append(back)
    fills = _gap_fills(tr, parts, abs(req.stop - req.start) / tr.scales[2], opt, req.progress)
    return _join(tr, parts, fills, req.start, req.stop, opt)


def _first_level(harmonics, samples):
    """((H, Ns) of the first branch, (harmonics auto, samples auto)); validates both."""
    auto_h, auto_s = harmonics == AUTO, samples == AUTO
    for name, v, auto in (("harmonics", harmonics, auto_h), ("samples", samples, auto_s)):
        if isinstance(v, str) and not auto:
            raise ValueError(f"{name} must be an integer or {AUTO!r}, got {v!r}")
    H = config.HB_HARMONICS if auto_h else V.positive_int("harmonics", harmonics, 1)
    if auto_s:
        return (H, max(config.HB_SAMPLES, 2 * H + 2)), (auto_h, auto_s)
    return (H, V.positive_int("samples", samples, 2 * H + 2)), (auto_h, auto_s)


def _check_levels(level, auto):
    """(H, Ns) of the harmonics check and of the samples check one level above ``level`` (None: not made)."""
    H, Ns = level
    h2 = 2 * H + 1
    by_h = (h2, max(Ns, 2 * h2 + 2) if auto[1] else Ns) if auto[0] else None
    if by_h is not None and by_h[1] < 2 * h2 + 2:
        by_h = None  # the samples fixed by the caller cannot carry more harmonics
    return by_h, ((H, 2 * Ns) if auto[1] else None)


def _next_level(level, auto, bad_h: bool, bad_s: bool):
    """The level the checks ask for, within ``config.HB_AUTO_MAX_*`` (equal to ``level``: no refinement).

    The samples first: with too few, the sampling error of the contact
    force also moves the solution with more harmonics, so H is raised
    only once the samples pass their check.
    """
    by_h, by_s = _check_levels(level, auto)
    if bad_s and by_s is not None:
        return by_s if by_s[1] <= config.HB_AUTO_MAX_SAMPLES else level
    if bad_h and by_h is not None and by_h[0] <= config.HB_AUTO_MAX_HARMONICS:
        return by_h
    return level


def _at_level(req: _Request, condensed: bool, X, level):
    """(tracker of the problem with ``level = (H, Ns)``, the harmonics X there in its scaled unknowns,
    zero above their H)."""
    problem = make_problem(req.system, condense=condensed, response_dofs=(req.dof,), harmonics=level[0],
                           samples=level[1], parameter=req.parameter, gamma=req.gamma)
    tr = _Tracker(problem, _scales(problem, req.start), req.dof)
    Xm = np.asarray(X).reshape(-1, problem.n)
    X0 = np.zeros((problem.nh, problem.n))
    X0[: min(Xm.shape[0], problem.nh)] = Xm[: problem.nh]
    return tr, X0.ravel() / tr.scales[0]


def _solve_at(req: _Request, condensed: bool, lam: float, X, level):
    """(amplitude of the response DOF (m; NaN where Newton failed), X) at parameter ``lam`` with
    ``level = (H, Ns)``, by Newton from the harmonics X (zero above their H)."""
    tr, y0 = _at_level(req, condensed, X, level)
    xs, _, ps = tr.scales
    y, ok, _ = newton(tr.residual, y0, lam / ps, req.options)
    return (tr.amplitudes(y)[0] if ok else math.nan), y * xs


def _first_step_amplitude(req: _Request, condensed: bool, lam: float, X, level) -> float:
    """Amplitude of the response DOF (m) after one Newton step from the harmonics X at parameter
    ``lam`` with ``level = (H, Ns)``: the solution's amplitude there to first order in the change
    (one evaluation; NaN where the step cannot be made)."""
    tr, y0 = _at_level(req, condensed, X, level)
    R, JX, _ = tr.residual(y0, lam / tr.scales[2])
    try:
        dy = np.linalg.solve(JX, -R)
    except np.linalg.LinAlgError:
        return math.nan
    y = y0 + dy
    return tr.amplitudes(y)[0] if np.all(np.isfinite(y)) else math.nan


def _change(amp: float, ref: float, scale: float) -> float:
    """|amp - ref| / scale (inf where the check solve failed)."""
    return abs(amp - ref) / scale if math.isfinite(amp) and scale > 0 else math.inf


def _peak_level(req: _Request, condensed: bool, pk: HBPeak, scale: float, level, auto):
    """(level at which the peak converges (or the bound), (harmonics change, samples change) at ``level``).

    The peak is solved with more harmonics and with more samples
    (:func:`_check_levels`); the changes are relative to ``scale`` (the
    highest peak of the branch, so that a small secondary peak asks for no
    more than its share of the curve). Where a change exceeds
    ``config.HB_AUTO_RTOL`` the peak is solved at the refined level and
    checked there again.
    """
    return _peak_levels(req, condensed, pk, scale, level, auto)[:2]


def _peak_levels(req: _Request, condensed: bool, pk, scale: float, level, auto):
    """:func:`_peak_level`, and whether the peak's check passed at the level returned (not at a bound)."""
    at, X, amp, first = level, pk.X, pk.amplitude_m, None
    while True:
        solved = {lv: _solve_at(req, condensed, pk.lam, X, lv) for lv in _check_levels(at, auto) if lv}
        ch = tuple(_change(solved[lv][0], amp, scale) if lv else math.nan for lv in _check_levels(at, auto))
        first = ch if first is None else first
        nxt = _next_level(at, auto, ch[0] > config.HB_AUTO_RTOL, ch[1] > config.HB_AUTO_RTOL)
        if nxt == at:
            return at, first, not (ch[0] > config.HB_AUTO_RTOL or ch[1] > config.HB_AUTO_RTOL)
        amp, X = solved[nxt] if nxt in solved else _solve_at(req, condensed, pk.lam, X, nxt)
        at = nxt
        if not math.isfinite(amp):
            return at, first, False


def _combined_target(req: _Request, condensed: bool, peaks, scale: float, level, auto, wanted):
    """The level of the next branch: the most harmonics and the most samples that the peaks ask for
    (``wanted``: their levels from :func:`_peak_level`).

    Where the peaks ask for both more harmonics and more samples, the
    harmonics are checked again at the higher samples first (the peaks
    solved there): a harmonics check made with too few samples also
    measures the sampling error of the contact force, and more harmonics
    cost as much as more samples in every AFT evaluation of the branch.
    """
    target = (max([level[0]] + [w[0] for w in wanted]), max([level[1]] + [w[1] for w in wanted]))
    if not (target[0] > level[0] and target[1] > level[1]):
        return target
    at = (level[0], target[1])
    again = []
    for pk in peaks:
        amp, X = _solve_at(req, condensed, pk.lam, pk.X, at)
        if not math.isfinite(amp):
            return target
        again.append(_peak_level(req, condensed, dataclasses.replace(pk, X=X, amplitude_m=amp),
                                 scale, at, auto)[0])
    return (max([at[0]] + [w[0] for w in again]), max([at[1]] + [w[1] for w in again]))


@dataclass(frozen=True)
class _Refine:
    """What :func:`_fixed_branch` returns where a peak asked for a finer level during the continuation:
    that level, the peak (a :class:`_Candidate`) and the level of the branch it stopped."""

    level: tuple
    peak: _Candidate = dataclasses.field(repr=False)
    stopped: tuple


@dataclass(frozen=True)
class _Candidate:
    """A peak of a branch being continued (the fields of :class:`HBPeak` that the discretisation check
    reads)."""

    lam: float
    X: np.ndarray
    amplitude_m: float


class _PeakWatch:
    """The tracker's monitor, and the discretisation check of the first level's resonances as soon as
    they are passed.

    The highest accepted point of the segment so far is checked once the
    amplitude has fallen below ``config.HB_AUTO_EARLY_DROP`` times its
    amplitude (and again for a higher point later): one Newton step from
    it with twice the samples (with 2H + 1 harmonics where the samples are
    fixed), one evaluation, gives the change of its amplitude to first
    order. Where that exceeds ``config.HB_AUTO_RTOL`` of its amplitude, the
    maximum is refined between the point and its neighbours and checked as
    the finished branch's peaks are (:func:`_peak_levels`,
    :func:`_combined_target`, relative to its own amplitude); where that
    converges at a finer level, the branch stops there (``target``: a
    :class:`_Refine`): the rest of it would be discarded, and continuing
    it costs more than the check. A stop is made relative to the peak's own
    amplitude, the finished branch's check relative to its highest peak:
    :func:`_adaptive_branch` keeps a stop only where the finished branch is
    converged and the peak asks for the same level relative to the
    finished branch's highest peak (:func:`_confirmed`). The finished
    branch's peaks are checked again, so a branch that passes here can
    still be refined.
    """

    def __init__(self, tr: _Tracker, req: _Request, level, auto, opt: ContinuationOptions):
        self.tr, self.req, self.level, self.auto, self.opt = tr, req, level, auto, opt
        self.points = []  # (log q, lam scaled, y) of the segment's accepted points
        self.top = None  # index in points of the highest point not checked yet
        self.checked = -math.inf  # log q of the highest point checked
        self.target = None

    def restart(self):
        """Forget the segment's points (a new segment starts)."""
        self.points, self.top = [], None

    def __call__(self, y, lam_s):
        stop = self.tr.monitor(y, lam_s)
        if stop is not None:
            return stop
        g = self.tr.observe(y, lam_s)
        pts = self.points
        pts.append((g, lam_s, np.array(y)))
        if not math.isfinite(g):
            return None
        if g > self.checked and (self.top is None or g > pts[self.top][0]):
            self.top = len(pts) - 1
            return None
        if self.top is None or g >= pts[self.top][0] + math.log(config.HB_AUTO_EARLY_DROP):
            return None
        i, self.top = self.top, None
        self.checked = pts[i][0]
        return self._check(i)

    def _check(self, i: int):
        tr = self.tr
        xs, _, ps = tr.scales
        g, lam_s, y = self.points[i]
        condensed = tr.problem.condensed
        by_h, by_s = _check_levels(self.level, self.auto)
        first = by_s if by_s is not None else by_h  # the cheaper check (more samples are checked first)
        if first is None or i == 0:
            return None
        amp = tr.amplitudes(y)[0]
        if _change(_first_step_amplitude(self.req, condensed, lam_s * ps, y * xs, first), amp, amp) \
                <= config.HB_AUTO_RTOL:
            return None  # the finished branch's check decides
        # the peak as the finished branch has it: refined between the point and its neighbours
        last = tr.last
        near = self.points[i - 1:i + 2]
        y_pk, lam_pk, g_pk, _ = refine_maximum(tr.residual, tr.observe, [p[2] for p in near],
                                               [p[1] for p in near], self.opt)
        tr.last = last
        if not g_pk >= g:
            y_pk, lam_pk = y, lam_s
        pk = _Candidate(lam=float(lam_pk * ps), X=y_pk * xs, amplitude_m=float(tr.amplitudes(y_pk)[0]))
        target, converged = _peak_target(self.req, condensed, pk, pk.amplitude_m, self.level, self.auto)
        if not converged or target == self.level:
            return None  # the finished branch decides
        self.target = _Refine(target, pk, self.level)
        name = tr.problem.parameter.name
        return ContinuationStatus.STOPPED, (f"the peak near {name} = {pk.lam:.6g} asks for H = {target[0]}, "
                                            f"Ns = {target[1]}")


def _peak_target(req: _Request, condensed: bool, pk, scale: float, level, auto):
    """(the level the peak alone asks for, checked from ``level`` with its changes relative to
    ``scale``; whether its check passed there)."""
    wanted, _, converged = _peak_levels(req, condensed, pk, scale, level, auto)
    return _combined_target(req, condensed, [pk], scale, level, auto, [wanted]), converged


def _confirmed(req: _Request, condensed: bool, stop: _Refine, scale: float, auto) -> bool:
    """Whether the peak that stopped a branch asks for the same level with its changes relative to
    ``scale`` (the highest peak of the finished branch) as relative to its own amplitude."""
    return _peak_target(req, condensed, stop.peak, scale, stop.stopped, auto) == (stop.level, True)


def _watched_branch(req: _Request, level, auto, levels, retry_failed: bool, watch: bool):
    """(branch, its level, the :class:`_Refine` of a stop or None): :func:`_fixed_branch` at ``level``
    (with ``watch``, watched by a :class:`_PeakWatch`), computed again at the level a peak asks for where
    one stops it, and with twice the samples where a branch asked for fails (after a stop by a peak, or
    where ``retry_failed``: a finer level may fail where the coarser went on, because a closed form's
    force jumps with the normal load and Newton fails at one sampling and not at the next). Each further
    level is appended to ``levels``."""
    br = _fixed_branch(req, level, auto, watch=watch)
    stop = None
    if isinstance(br, _Refine):
        stop = br
        level, retry_failed = stop.level, True
        levels.append(level)
        br = _fixed_branch(req, level, auto)
    while retry_failed and br.status is ContinuationStatus.FAILED and auto[1] \
            and 2 * level[1] <= config.HB_AUTO_MAX_SAMPLES:
        level = (level[0], 2 * level[1])
        levels.append(level)
        br = _fixed_branch(req, level, auto)
    return br, level, stop


def _worst(values) -> float:
    """Largest of the values that are not NaN (NaN when there is none)."""
    v = [x for x in values if not math.isnan(x)]
    return max(v) if v else math.nan


def _adaptive_branch(req: _Request, level, auto, watch: bool = True) -> HBBranch:
    """The branch at ``level``, computed again at a finer level while its peaks ask for one (``auto``:
    which of (harmonics, samples) may change); with its :class:`DiscretisationCheck`.

    With ``watch``, the first branch stops at a passed resonance that asks
    for a finer level (:class:`_PeakWatch`); where the finished branch does
    not confirm such a stop (it is not converged, or the peak asks for
    another level relative to the finished branch's highest peak: the stop
    was made at a resonance lower than one found later), the whole choice
    is made again without stops.
    """
    first = level
    levels = [level]
    if not any(auto):
        return _fixed_branch(req, level).branch()
    br, level, stop = _watched_branch(req, level, auto, levels, False, watch)
    while True:
        scale = max([pk.amplitude_m for pk in br.peaks], default=0.0)
        checks = [_peak_level(req, br.problem.condensed, pk, scale, level, auto) for pk in br.peaks]
        target = _combined_target(req, br.problem.condensed, br.peaks, scale, level, auto, [c[0] for c in checks])
        if target == level:
            break
        levels.append(target)
        br, level, _ = _watched_branch(req, target, auto, levels, br.status is not ContinuationStatus.FAILED, False)
    by_h, by_s = _check_levels(level, auto)
    ch_h, ch_s = _worst(c[1][0] for c in checks), _worst(c[1][1] for c in checks)
    converged = not (ch_h > config.HB_AUTO_RTOL or ch_s > config.HB_AUTO_RTOL)
    if stop is not None and not (converged and _confirmed(req, br.problem.condensed, stop, scale, auto)):
        return _adaptive_branch(req, first, auto, watch=False)
    check = DiscretisationCheck(harmonics_auto=auto[0], samples_auto=auto[1], levels=tuple(levels),
                                check_harmonics=by_h[0] if by_h else 0, check_samples=by_s[1] if by_s else 0,
                                harmonics_change=ch_h, samples_change=ch_s, peaks=len(checks),
                                rtol=config.HB_AUTO_RTOL, converged=converged)
    br = br.branch()
    message = br.message
    if not converged:
        message += (f"; the peak amplitude is not converged in the discretisation at its bound (H = {level[0]}, "
                    f"Ns = {level[1]}): it changes by {100 * _worst([ch_h, ch_s]):.3g} % with "
                    f"{check.check_harmonics or level[0]} harmonics or {check.check_samples or level[1]} samples "
                    f"(tolerance {100 * config.HB_AUTO_RTOL:g} %)")
    return dataclasses.replace(br, discretisation=check, message=message)


#: segment statuses after which a second segment is continued back from the end of the range
_GO_BACK = (ContinuationStatus.UNBOUNDED, ContinuationStatus.FAILED, ContinuationStatus.TURNED_BACK)


def _point_status(res: ContinuationResult) -> np.ndarray:
    """PointStatus of every point of one segment."""
    out = np.full(res.lam.size, PointStatus.JOINED, dtype=object)
    if res.lam.size:
        out[res.gap] = PointStatus.AFTER_JUMP
        out[res.corner] = PointStatus.CORNER
        out[0] = PointStatus.START
        # a segment that turned back ends on the start of the range (landed there): not short of anything
        if not res.status.ok and res.status is not ContinuationStatus.TURNED_BACK:
            out[-1] = PointStatus.STOPPED
    return out


def _join(tr: _Tracker, parts, fills, start, stop, opt) -> _Draft:
    """The branch of the continued segments (unscaled), with its status, peaks and coverage.

    ``parts``: the segment from the start and the one continued back from
    the end; they decide the status. ``fills``: the segments continued back
    over jumps with the points the jumps left (:func:`_gap_fills`),
    appended after them.
    """
    problem = tr.problem
    xs, _, ps = tr.scales
    status, message, uncovered = _coverage(parts, start, stop, ps, problem.parameter.name)
    message += _fills_message([f for f, _ in fills], ps, problem.parameter.name)
    main = len(parts)
    parts = [*parts, *(f for f, _ in fills)]
    lam = np.concatenate([p.lam * ps for p in parts])
    joined = _Parts(
        lam=lam,
        X=np.concatenate([p.y * xs for p in parts]) if lam.size else np.empty((0, problem.size)),
        segment=np.concatenate([np.full(p.lam.size, i) for i, p in enumerate(parts)]).astype(int),
        fold=np.zeros(lam.size, dtype=bool),
        gap=np.concatenate([p.gap for p in parts]).astype(bool),
        point_status=np.concatenate([_point_status(p) for p in parts]),
        counters={**{k: sum(p.counters.get(k, 0) for p in parts) for k in parts[0].counters},
                  "segments": len(parts)},
    )
    if joined.counters.get("jumps", 0):
        message += (f"; {joined.counters['jumps']} jump(s) over discontinuities of the contact force "
                    "(points with point_status 'after-jump')")
    logqs = [np.array([tr.observe(y, 0.0) for y in p.y]) for p in parts]
    peaks = [pk for i, (p, g) in enumerate(zip(parts[:main], logqs)) for pk in _peaks(tr, p, g, i, opt)]
    peaks += [pk for k, (f, y_left) in enumerate(fills)
              for pk in _fill_peak(tr, f, logqs[main + k], tr.observe(y_left, 0.0), main + k, opt)]
    logq = np.concatenate(logqs)
    joined = dataclasses.replace(joined, fold=_turning_mask(joined.lam, logq, joined.segment, joined.gap, start, stop))
    return _Draft(tr, status, message, joined, tuple(peaks), tuple(uncovered))


class _FillMonitor:
    """The tracker's monitor, and the end of a segment continued back over a jump once it is past the point
    the jump left (parameter ``lam_left``, scaled; coming from ``lam_after``) and below its amplitude: from
    there on it retraces the branch already computed."""

    def __init__(self, tr: _Tracker, lam_left: float, lam_after: float, y_left):
        self.tr, self.lam_left, self.g_left = tr, lam_left, tr.observe(y_left, 0.0)
        self.direction = math.copysign(1.0, lam_left - lam_after)

    def __call__(self, y, lam_s):
        stop = self.tr.monitor(y, lam_s)
        if stop is not None:
            return stop
        if (lam_s - self.lam_left) * self.direction > 0 and self.tr.observe(y, lam_s) < self.g_left:
            name = self.tr.problem.parameter.name
            return ContinuationStatus.COMPLETE, (f"passed the point the jump left ({name} = "
                                                 f"{self.lam_left * self.tr.scales[2]:.6g}) below its amplitude")
        return None


def _may_hide_a_peak(tr: _Tracker, p: ContinuationResult, i: int) -> bool:
    """True when the amplitude rises into the jump to point i of segment p and falls after it (a maximum
    may lie in the stretch passed over); False for a jump on a flank (the closed forms' force jumps)."""
    if i < 2 or i + 1 >= p.lam.size or p.gap[i - 1] or p.gap[i + 1]:
        return False
    g = [tr.observe(p.y[k], 0.0) for k in (i - 2, i - 1, i, i + 1)]
    return bool(g[1] >= g[0] and g[3] <= g[2])


def _fills_message(fills, ps, name) -> str:
    """Where each segment continued back over a jump went, for the branch's message."""
    out = ""
    for f in fills:
        if f.lam.size:
            out += (f"; traced back from the point after a jump at {name} = {f.lam[0] * ps:.6g}: "
                    f"{f.status} ({f.message})")
    return out


def _span(p: ContinuationResult, ps):
    """(lo, hi) of a segment's parameter values (unscaled), or None for an empty one."""
    return (float(p.lam.min() * ps), float(p.lam.max() * ps)) if p.lam.size else None


def _holes(spans, lo, hi):
    """Parts of [lo, hi] outside the union of the intervals ``spans``."""
    out, at = [], lo
    for a, b in sorted(s for s in spans if s is not None):
        if a > at:
            out.append((at, min(a, hi)))
        at = max(at, b)
    if at < hi:
        out.append((at, hi))
    return [(a, b) for a, b in out if b > a]


def _coverage(parts, start, stop, ps, name):
    """(status, message, uncovered intervals) of a branch made of its segments.

    ``complete`` when the segments cover [start, stop]: the first one
    reached ``stop``, or the one continued back from ``stop`` reached
    ``start`` or the parameter where the first one stopped; ``unbounded``
    when both ended unbounded (the response has no bound between them);
    otherwise the status of the first segment that neither completed nor
    ended unbounded (a failure of the segment continued back is not hidden
    behind an unbounded first one), with the parts of the range not
    computed named in the message.
    """
    lo, hi = min(start, stop), max(start, stop)
    first = parts[0]
    message = first.message
    if len(parts) > 1:
        message += f"; continued back from {name} = {stop:.6g}: {parts[1].status} ({parts[1].message})"
    holes = _holes([_span(p, ps) for p in parts], lo, hi)
    if first.status is ContinuationStatus.COMPLETE or (len(parts) > 1 and not holes):
        status = ContinuationStatus.COMPLETE
    elif len(parts) > 1 and all(p.status is ContinuationStatus.UNBOUNDED for p in parts):
        status = ContinuationStatus.UNBOUNDED
    else:
        status = next((p.status for p in parts if not p.status.ok and p.status is not ContinuationStatus.UNBOUNDED),
                      first.status)
    if holes:
        where = ", ".join(f"{a:.6g} to {b:.6g}" for a, b in holes)
        what = "no bounded response" if status is ContinuationStatus.UNBOUNDED else "not computed"
        message += f"; {what} for {name} from {where}"
    return status, message, holes


def _peaks(tr: _Tracker, res: ContinuationResult, g, segment: int, opt) -> list:
    """Maxima of the response amplitude along one segment (log q at its points: g), refined between
    its points (HBPeak)."""
    if res.lam.size < 3:
        return []
    return [_refined_peak(tr, res, g, i, segment, opt) for i in local_maxima(g, res.gap, config.HB_PEAK_PROMINENCE)]


def _refined_peak(tr: _Tracker, res: ContinuationResult, g, i: int, segment: int, opt) -> HBPeak:
    """The HBPeak near the interior point i of a segment, refined between its neighbours."""
    y, lam_s, gv, ok = refine_maximum(tr.residual, tr.observe, res.y[i - 1:i + 2], res.lam[i - 1:i + 2], opt)
    if not gv >= g[i]:  # the refinement found nothing higher: keep the branch point
        y, lam_s, gv, ok = res.y[i], res.lam[i], g[i], False
    return _peak(tr, y, lam_s, segment, ok)


def _peak(tr: _Tracker, y, lam_s: float, segment: int, refined: bool, at_stop: bool = False) -> HBPeak:
    """HBPeak at the scaled unknowns y and parameter lam_s."""
    xs, _, ps = tr.scales
    lam = float(lam_s * ps)
    amp = tr.amplitudes(y)[0]
    gam = lam if tr.problem.parameter is GAMMA else float(tr.problem.gamma_fixed)
    return HBPeak(lam=lam, gamma=gam, X=y * xs, amplitude_m=float(amp), amplitude_q=float(tr.q(amp)),
                  segment=segment, refined=refined, at_stop=at_stop)


def _fill_peak(tr: _Tracker, fill: ContinuationResult, g, g_left: float, segment: int, opt) -> list:
    """[HBPeak] of a segment continued back over a jump: its highest point when that lies above both ends
    of the jump (log q: g along the fill, g_left at the point the jump left), else [].

    Refined between its neighbours where it is an interior point; where the
    curve could not be followed past it (the fill's last point, or the last
    before a jump of its own) it is reported as found at a stop. The rest of
    a fill retraces known parts of the branch (or zigzags where it stalled):
    its other maxima are not peaks of the stretch the jump passed over.
    """
    if fill.lam.size < 2 or not np.isfinite(g).all():
        return []
    j = int(np.argmax(g))
    if not (g[j] > g[0] and g[j] > g_left):
        return []
    if j == g.size - 1 or fill.gap[j + 1] or fill.gap[j]:
        return [_peak(tr, fill.y[j], fill.lam[j], segment, False, at_stop=True)]
    return [_refined_peak(tr, fill, g, j, segment, opt)]


def _turning_mask(lam, observed, segment, gap, start, stop):
    """Folds: points where the parameter is extremal along a segment, beyond a dead band.

    A reversal of the parameter counts once it exceeds
    ``config.HB_TURNING_BAND`` of the range, or once log q has moved by
    more than ``config.HB_TURNING_BAND_LOG_Q`` while the parameter is still
    short of the extreme (a fold whose two branches are close in the
    parameter but far apart in amplitude). The jitter of points at a
    non-smooth corner (onset of slip or separation, where the branch keeps
    going) is within both bands and does not count.
    """
    m = np.zeros(lam.size, dtype=bool)
    band = config.HB_TURNING_BAND * abs(stop - start)
    for sgm in np.unique(segment):
        idx = np.flatnonzero(segment == sgm)
        tp = turning_points(lam[idx], gap[idx], band=band, observed=observed[idx],
                            observed_band=config.HB_TURNING_BAND_LOG_Q)
        m[idx[tp]] = True
    return m


def branch_dataset(branch: HBBranch, response_dof: int | None = None):
    """xarray Dataset of a branch (dims ``point``, ``harmonic``, ``peak``).

    Variables per point: ``gamma``, the parameter (if not gamma),
    ``amplitude_q`` (kt X / fy of the first contact, X = half
    peak-to-peak of x(t) of ``response_dof``), ``amplitude_m`` (X, m),
    ``offset_m`` (mean, m), ``max_abs_m`` (m), ``stable``, ``fold``
    (turning points: the parameter is extremal along the computed branch,
    beyond a dead band of ``config.HB_TURNING_BAND`` of the range, so that
    the corners of a piecewise-smooth branch, where it keeps its
    direction, are not folds), ``point_status`` (:class:`PointStatus`:
    how the point joins the one before it; a line is drawn only to
    ``joined`` and ``corner`` points), ``branch`` (segment index), ``gap``
    (reached by a jump), ``growth`` (max Re(s)/w of the Floquet
    exponents), ``aft_passes`` (periods marched), ``force_period`` (1; 2
    when the law alternated between two cycles and their mean was used; 0
    if the force did not repeat), ``harmonic_amplitude_m`` (dims point,
    harmonic: sqrt(a_k^2 + b_k^2), |a_0| for k = 0). Per peak (dim
    ``peak``): ``peak_gamma``, ``peak_<parameter>`` (if not gamma),
    ``peak_amplitude_q``, ``peak_amplitude_m``, ``peak_branch``,
    ``peak_refined``, ``peak_at_stop`` (:attr:`HBPeak.at_stop`).

    Attributes: ``status`` (:class:`~jointdyn.continuation.ContinuationStatus`;
    ``complete`` only when the range is covered), ``message`` (where and
    why segments stopped), ``uncovered`` (parts of the range without
    points, e.g. ``"1.164-1.185"``; empty when none), ``peaks``,
    ``peak_gamma`` and ``peak_amplitude_q`` (the highest peak, NaN
    without one), ``folds``, ``unstable_points`` and the counters.
    """
    import xarray as xr

    p = branch.problem
    dof = branch.response_dof if response_dof is None else response_dof
    if not 0 <= dof < p.system.ndof:
        raise ValueError(f"response_dof must be in [0, {p.system.ndof - 1}], got {dof!r}")
    law = contact_of(p.system).law
    amp, off, mx = branch.response(dof)
    Xd = p.dof_coefficients(branch.X, dof, branch.lam) if branch.X.size else np.empty((0, p.nh))
    harm = np.empty((Xd.shape[0], p.H + 1))
    harm[:, 0] = np.abs(Xd[:, 0])
    for k in range(1, p.H + 1):
        harm[:, k] = np.hypot(Xd[:, 2 * k - 1], Xd[:, 2 * k])
    qs = law.kt / law.fy if law.fy > 0 else np.nan
    data = {
        "gamma": ("point", branch.gamma()),
        "amplitude_q": ("point", qs * amp),
        "amplitude_m": ("point", amp),
        "offset_m": ("point", off),
        "max_abs_m": ("point", mx),
        "stable": ("point", branch.stable),
        "fold": ("point", branch.fold),
        "point_status": ("point", np.array([str(s) for s in branch.point_status], dtype=str)),
        "branch": ("point", branch.segment),
        "gap": ("point", branch.gap),
        "growth": ("point", branch.growth),
        "aft_passes": ("point", branch.passes),
        "force_period": ("point", branch.force_period),
        "harmonic_amplitude_m": (("point", "harmonic"), harm),
        **_peak_variables(branch, dof, qs),
    }
    if branch.parameter != "gamma":
        data[branch.parameter] = ("point", branch.lam)
    attrs = {"gamma": {"long_name": "w / w0"}, "amplitude_q": {"long_name": "kt X / fy", "units": "1"},
             **{v: {"units": "m"} for v in ("amplitude_m", "offset_m", "max_abs_m", "harmonic_amplitude_m",
                                            "peak_amplitude_m")},
             "point_status": {"flag_meanings": " ".join(s.value for s in PointStatus)}}
    # variables built with their attributes (no DataArray round trips afterwards)
    data = {k: xr.Variable(dims, np.asarray(v), attrs=attrs.get(k)) for k, (dims, v) in data.items()}
    ds = xr.Dataset(data, coords={"point": np.arange(branch.lam.size), "harmonic": np.arange(p.H + 1),
                                  "peak": np.arange(len(branch.peaks))})
    ds.attrs.update(_branch_attrs(branch, dof, ds))
    return ds


def _peak_variables(branch: HBBranch, dof: int, qs: float) -> dict:
    """Dataset variables on dim ``peak`` (see :func:`branch_dataset`)."""
    pk = branch.peaks
    p = branch.problem
    amp = [k.amplitude_m if dof == branch.response_dof else p.amplitudes(k.X, dof)[0] for k in pk]
    out = {
        "peak_gamma": ("peak", np.array([k.gamma for k in pk], dtype=float)),
        "peak_amplitude_q": ("peak", qs * np.array(amp, dtype=float)),
        "peak_amplitude_m": ("peak", np.array(amp, dtype=float)),
        "peak_branch": ("peak", np.array([k.segment for k in pk], dtype=int)),
        "peak_refined": ("peak", np.array([k.refined for k in pk], dtype=bool)),
        "peak_at_stop": ("peak", np.array([k.at_stop for k in pk], dtype=bool)),
    }
    if branch.parameter != "gamma":
        out["peak_" + branch.parameter] = ("peak", np.array([k.lam for k in pk], dtype=float))
    return out


def _branch_attrs(branch: HBBranch, dof: int, ds) -> dict:
    """Dataset attributes of a branch (see :func:`branch_dataset`)."""
    p = branch.problem
    top = int(np.argmax(ds.peak_amplitude_q.values)) if len(branch.peaks) else None
    return dict(
        status=branch.status.value,
        message=branch.message,
        uncovered=", ".join(f"{a:.6g}-{b:.6g}" for a, b in branch.uncovered),
        method="hb",
        parameter=branch.parameter,
        harmonics=p.H,
        samples=p.Ns,
        response_dof=dof,
        points=int(branch.lam.size),
        peaks=len(branch.peaks),
        peak_gamma=float(ds.peak_gamma.values[top]) if top is not None else math.nan,
        peak_amplitude_q=float(ds.peak_amplitude_q.values[top]) if top is not None else math.nan,
        folds=int(branch.fold.sum()),
        unstable_points=int((~branch.stable).sum()),
        stability="hill" if np.all(np.isfinite(branch.growth)) else "not-computed",
        condensed=int(p.condensed),
        unknown_dofs=int(p.n),
        max_aft_passes=int(branch.passes.max()) if branch.passes.size else 0,
        force_period_2_points=int((branch.force_period == 2).sum()),
        force_not_periodic_points=int((branch.force_period == 0).sum()),
        **{f"counter_{k}": int(v) for k, v in branch.counters.items()},
        **discretisation_attrs(branch),
    )


def discretisation_attrs(branch: HBBranch) -> dict:
    """Attributes of the choice of harmonics and samples and of its check (see :class:`DiscretisationCheck`).

    ``harmonics_choice`` and ``samples_choice`` (``auto`` or ``fixed``),
    ``discretisation_levels`` (the (H, Ns) of every branch computed, e.g.
    ``"7x128, 7x256"``), ``check_harmonics`` and ``check_samples`` (of the
    check solves, 0 where none was made), ``check_harmonics_change`` and
    ``check_samples_change`` (largest relative change of a peak amplitude;
    NaN without a check), ``check_rtol``, ``check_converged`` (1/0) and
    ``check_peaks``.
    """
    d = branch.discretisation
    if d is None:
        p = branch.problem
        return dict(harmonics_choice="fixed", samples_choice="fixed", discretisation_levels=f"{p.H}x{p.Ns}")
    return dict(
        harmonics_choice="auto" if d.harmonics_auto else "fixed",
        samples_choice="auto" if d.samples_auto else "fixed",
        discretisation_levels=", ".join(f"{h}x{n}" for h, n in d.levels),
        check_harmonics=d.check_harmonics,
        check_samples=d.check_samples,
        check_harmonics_change=float(d.harmonics_change),
        check_samples_change=float(d.samples_change),
        check_rtol=float(d.rtol),
        check_converged=int(d.converged),
        check_peaks=d.peaks,
    )


def frc_hb(system: System, gamma_start: float, gamma_stop: float, *, harmonics: int | str = AUTO,
           samples: int | str = AUTO, max_step: float | None = None, response_dof: int | None = None,
           options: ContinuationOptions | None = None, progress: bool | None = None, condense: bool | None = None,
           **overrides):
    """Frequency-response curve by harmonic balance and arc-length continuation.

    Harmonics 0..H of every DOF (normalised time tau = w t), contact forces
    by alternating frequency-time with ``samples`` per period (re-contact
    instants located exactly between samples), exact Jacobians by forward
    mode through the march of the contact laws, stability by Hill's method,
    folds as turning points, peaks refined between the points. See
    :func:`continue_hb` for the parameters.

    Parameters
    ----------
    system : System
    gamma_start, gamma_stop : float
        Range of gamma = w / w0 (> 0, distinct); the branch starts at
        ``gamma_start`` from the stuck-contact linear solution.
    harmonics : int or "auto"
        H >= 1, or chosen from the convergence of the peaks (default; see
        :func:`continue_hb`).
    samples : int or "auto"
        >= 2H + 2, or chosen likewise (default).
    max_step : float, optional
        Largest gamma spacing between consecutive points (e.g. the STEP of
        a gamma grid; default ``config.HB_MAX_GAMMA_STEP``); the chord
        bound (``chord_tol``) applies in any case.
    response_dof : int, optional
        DOF whose response is reported (default ``system.response_dof``).
    options : ContinuationOptions, optional
        Step control; keyword arguments override its fields (``ds``,
        ``ds_max``, ``max_points``, ``chord_tol``, ``predictor``, ...).
    condense : bool, optional
        Condense exactly onto the contact DOFs (None: by size; see
        :func:`continue_hb`).

    Returns
    -------
    xarray.Dataset
        Dims ``point`` and ``peak``; variables ``gamma``, ``amplitude_q``,
        ``amplitude_m``, ``offset_m``, ``max_abs_m``, ``stable``, ``fold``,
        ``point_status``, the refined peaks (``peak_gamma``,
        ``peak_amplitude_q``, ...) and more (see :func:`branch_dataset`);
        attrs ``status`` (``complete`` only when the range is covered;
        ``unbounded``, ``failed``, ``turned-back``, ``max-points``),
        ``message``, ``uncovered``, ``harmonics``, ``samples`` and the
        counters (``counter_*``). A branch that is not complete is never
        silent: its status, message and the ``stopped`` point say where.
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    br = continue_hb(system, V.positive("gamma_start", gamma_start), V.positive("gamma_stop", gamma_stop),
                     parameter=GAMMA, harmonics=harmonics, samples=samples, max_step=max_step,
                     response_dof=response_dof, options=options, progress=progress, condense=condense, **overrides)
    return branch_dataset(br)


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
    amp, off, mx = problem.amplitudes(X, response_dof, lam)
    stable, growth, mult = problem.hill_stability(ev.JX, problem.omega(lam))
    return HBSolution(problem=problem, X=X, converged=bool(converged), iterations=int(iterations),
                      residual_norm=float(np.max(np.abs(ev.R))), amplitude_m=amp, offset_m=off, max_abs_m=mx,
                      stable=stable, growth=growth, multipliers=mult, aft_info=ev.info)


def harmonic_balance(system: System, gamma: float, *, harmonics: int = config.HB_HARMONICS,
                     samples: int = config.HB_SAMPLES, guess=None, response_dof: int = 0,
                     tol: float = config.CONT_TOL, max_iter: int = config.HB_SOLVE_MAX_ITER,
                     condense: bool | None = None) -> HBSolution:
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
    condense : bool, optional
        Condense exactly onto the contact DOFs (None: by size; see
        :func:`continue_hb`). The unknowns X (and ``guess``) are then the
        harmonics of the retained DOFs ``problem.dofs``; stability is
        computed only when the full problem is small
        (:mod:`jointdyn.hb.condense`).

    Returns
    -------
    HBSolution
        ``converged`` False when Newton failed (no exception).
    """
    gamma = V.positive("gamma", gamma)
    # the forcing amplitude as the (fixed) parameter: a problem at this gamma
    problem = make_problem(system, condense=condense, harmonics=harmonics, samples=samples, parameter="f1",
                           gamma=gamma)
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
                         progress=False, condense=problem.condensed)
        if br.status is ContinuationStatus.COMPLETE and br.lam.size and br.lam[-1] == f1:
            y, ok, it = newton(residual, br.X[-1] / xs, 0.0, tol=tol, max_iter=max_iter)
    return _make_solution(problem, y * xs, ok, it, response_dof)
