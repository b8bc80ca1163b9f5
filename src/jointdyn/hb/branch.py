"""One harmonic-balance branch at a fixed discretisation (H harmonics, Ns samples).

:func:`continued_branch` follows the HB solutions of one problem in its
parameter with the generic arc-length continuation of
:mod:`jointdyn.continuation`: the tracker (scaled residual, observable,
monitor), the segments (from the start, and back from the end after a stop
short of it), the segments continued back over jumps, the peaks, the folds
and the coverage of the range; :meth:`_Draft.branch` adds the per-point AFT
diagnostics and Hill stability (:mod:`jointdyn.hb.stability`).
:func:`solve_point` solves one point, with the homotopy in the forcing
amplitude that also starts a branch in gamma where Newton fails from the
linear solution. The automatic choice of harmonics and samples
(:mod:`jointdyn.hb.discretisation`) and the entry points
(:mod:`jointdyn.hb.frc`) are above this module.

Unbounded responses
-------------------
Without viscous damping the Coulomb-saturated oscillator has no steady
state at gamma = 1 when friction is too weak (Den Hartog: R/F < pi/4).
A branch point is declared ``unbounded`` when

* q = kt X / fy exceeds ``HBOptions.unbounded_q`` (hard bound, any system),
  or the corrector fails at the smallest step beyond
  ``HBOptions.unbounded_fail_fraction`` of it; or
* the describing-function saturation test holds: C = 0, q exceeds
  ``HBOptions.saturation_q``, every contact slips (macroslip or
  separation) over at least ``HBOptions.saturation_slip_fraction`` of the
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

import contextlib
import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .._threads import blas_threads
from ..continuation import (
    START_EXTRAPOLATION,
    ContinuationOptions,
    ContinuationResult,
    ContinuationStatus,
    ParameterProgress,
    stage_progress,
    continuation,
    local_maxima,
    make_options,
    newton,
    preconditioned_by,
    refine_maximum,
    turning_points,
)
from ..damping import has_damping
from ..fourier import derivative_matrix
from ..laws import MACROSLIP, SEPARATION
from ..systems import System
from ._aft import INFO_ERROR, INFO_PASSES, INFO_PERIOD
from .condense import make_problem
from .levels import Level
from .options import HBOptions
from .parameters import F1, GAMMA
from .problem import HBProblem, reference_scales
from .floquet import companion_rows, confirmed_stability, growths, stability_method
from .results import HBBranch, HBPeak, PointStatus, sliding_as_a_whole
from .stability_options import StabilityOptions
from .stability_schedule import checked_labels

__all__ = ["continued_branch", "solve_point"]



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
    stability: StabilityOptions = StabilityOptions()
    hb: HBOptions = HBOptions()


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
    """HBBranch of the continued points: AFT diagnostics of every point and the Hill stability of the points
    :func:`~jointdyn.hb.stability_schedule.checked_labels` asks for (every point by default).

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
    for i in range(n):
        ev = _kept(tr, X[i], lam[i], jacobian=False)
        if len(ev) > 2:
            response0[i] = ev[2]
        ev = ev[1]
        passes[i] = int(ev.info[INFO_PASSES])
        periodic_error[i] = ev.info[INFO_ERROR]
        force_period[i] = int(ev.info[INFO_PERIOD])
    method = stability_method(problem, tr.stability)
    growth = np.full(n, np.nan)
    if method == "none":
        stable, checked, confirmed = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool), 0
    else:
        stable, checked, confirmed = _stability(tr, parts, growth, method)
    counters = {**parts.counters, "monodromy_checks": confirmed}
    # folds need the stability on both sides; without it (no stability asked for) the turning points stand
    fold = (_saddle_nodes(parts.fold, stable, parts.segment, problem.options.fold_window)
            if np.all(np.isfinite(growth[checked])) and (checked.any() or n == 0) else parts.fold)
    return HBBranch(problem=problem, parameter=problem.parameter.name, status=status, message=message, lam=lam,
                    X=X, segment=parts.segment, fold=fold, gap=parts.gap, counters=counters,
                    stable=stable, growth=growth, passes=passes,
                    periodic_error=periodic_error, force_period=force_period, response0=response0,
                    point_status=parts.point_status, peaks=tuple(peaks), uncovered=tuple(uncovered),
                    response_dof=tr.dof, stability=_STABILITY_NAMES[method], stability_checked=checked,
                    stability_check_every=tr.stability.check_every)


def _kept(tr, X, lam, jacobian: bool, dense: bool = False):
    """(X, evaluation, amplitudes...) at a point of the branch: the continuation monitor's where it kept the
    very same X (and its Jacobian when ``jacobian``), else evaluated again (dense when ``dense``)."""
    ev = tr.evaluations.get(float(lam))
    if ev is None or ev[0].tobytes() != X.tobytes() or (jacobian and ev[1].JX is None):  # not kept for X
        ev = (X, tr.evaluate(X, lam, dense), *(ev[2:] if ev is not None and ev[1].JX is None else ()))
    return ev


def _stability(tr, parts: _Parts, growth, method: str):
    """(stable, checked, monodromy checks) of the branch's points; fills ``growth`` (max Re(s) / w) at the
    checked points. Dense Hill on chunks of points whose Jacobians fit in ``HBOptions.jacobian_budget_bytes``,
    or shift-invert Arnoldi point by point (``StabilityOptions.method_for``); the points checked are those
    :func:`~jointdyn.hb.stability_schedule.checked_labels` asks for (``StabilityOptions.check_every``)."""
    problem, opts = tr.problem, tr.stability
    lam, X = parts.lam, parts.X
    n = lam.size
    ws = np.array([problem.omega(v) for v in lam])
    dense = method == "dense"
    chunk = max(1, min(n, problem.options.jacobian_budget_bytes // (8 * problem.size * problem.size))) if dense else 1
    lapack = method == "arnoldi" or (dense and companion_rows(problem) > opts.small_eig)
    confirmed = [0]

    def label_of(idx):
        for lo in range(0, idx.size, chunk):
            part = idx[lo:lo + chunk]
            JXs = [_kept(tr, X[i], lam[i], jacobian=True, dense=dense)[1].JX for i in part]
            if dense:
                JXs = np.array([J if isinstance(J, np.ndarray) else J.toarray() for J in JXs])  # kept sparse
            growth[part] = growths(problem, JXs, ws[part], opts, method)
            bar.update(part.size)
        ok, m = confirmed_stability(problem, X[idx], lam[idx], growth[idx], opts)
        confirmed[0] += m
        return ok

    with stage_progress(n, f"stability ({method})", tr.progress, unit="point") as bar, \
            (blas_threads() if lapack else contextlib.nullcontext()):
        stable, checked = checked_labels(parts.segment, parts.gap, parts.fold, opts.check_every, label_of)
        bar.update(n - int(checked.sum()))  # the points whose label is carried over
    return stable, checked, confirmed[0]


#: the name of each stability method in an HBBranch (and the ``stability`` attribute of its Dataset)
_STABILITY_NAMES = {"dense": "hill", "arnoldi": "hill-arnoldi", "none": "not-computed"}


def _saddle_nodes(turning, stable, segment, window: int):
    """The turning points that can be folds: an unstable point next to them along the branch.

    At a fold of a smooth branch a real Floquet multiplier crosses +1, so
    the number of unstable multipliers changes by one there and one side of
    it is unstable. A turning point is kept when the stretch to the
    neighbouring turning point on either side (or, without one, the
    ``window`` points on that side, ``HBOptions.fold_window``) holds an unstable point;
    on a piecewise-smooth branch the change of stability can lie a few
    points before the extreme of the parameter. Turning points with stable
    points all around are zigzags of the branch at corners or jumps of a
    closed-form contact force, not folds: a sweep does not jump there.
    """
    out = np.zeros_like(turning)
    k = window
    for sgm in np.unique(segment):
        idx = np.flatnonzero(segment == sgm)
        tp = np.flatnonzero(turning[idx])
        for j, i in enumerate(tp):
            lo = tp[j - 1] if j > 0 else max(i - k, 0)
            hi = tp[j + 1] if j + 1 < tp.size else min(i + k, idx.size - 1)
            out[idx[i]] = not stable[idx[lo:hi + 1]].all()
    return out


def _scales(problem: HBProblem, start: float):
    """(xs, fs, ps): units of the unknowns (fy/kt, m), of the residual (max(F1, fy), N) and of the parameter."""
    kt, fy = reference_scales(problem.system)
    xs = fy / kt if fy > 0 else 1.0
    fs = max(problem.f1_ref, fy, 1e-300)
    return xs, fs, problem.parameter.scale(problem, start)


def _saturation_test(problem: HBProblem, ev, X, q, lam):
    """Describing-function saturation test (module docstring); None or reason."""
    opts = problem.options
    if q < opts.saturation_q or has_damping(problem.system.C) or problem.system.ndof != 1:
        return None
    for code in ev.code:
        slip = np.mean((code == MACROSLIP) | (code == SEPARATION))
        if slip < opts.saturation_slip_fraction:
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

    def __init__(self, problem: HBProblem, scales, dof: int, stability: StabilityOptions | None = None,
                 progress=False):
        self.problem = problem
        #: how the stability of the branch's points is computed, and whether its stages show progress
        self.stability = StabilityOptions() if stability is None else stability
        self.progress = progress
        self.scales = scales
        self.dof = dof
        self.kt, self.fy = reference_scales(problem.system)
        self.last = None
        #: parameter value -> (X, evaluation, amplitudes of the response DOF) at accepted points
        self.evaluations = {}
        #: the amplitudes of the last few unknowns asked for (observable and monitor share them)
        self._amps = {}
        #: the amplitudes of every accepted point (the branch's observable asks for them again)
        self._accepted_amps = {}
        #: how the Jacobian is evaluated: dense up to ``HBOptions.dense_max_unknowns``, beyond as
        #: :meth:`HBProblem.large_jacobian` says (sparse or harmonic blocks); the stability's dense Hill
        #: re-evaluates the points it needs densely (:meth:`evaluate`)
        self.kind = "dense" if problem.dense_jacobians() else problem.large_jacobian()

    def residual(self, y, lam_s):
        xs, fs, ps = self.scales
        if self.kind == "sparse":
            ev = self.problem.evaluate_sparse(y * xs, lam_s * ps)
            ev.scaled = (ev.R / fs, ev.JX * (xs / fs), ev.Jp * (ps / fs))
        elif self.kind == "blocks":
            ev = self.problem.evaluate_blocks(y * xs, lam_s * ps)
            ev.scaled = (ev.R / fs, ev.JX.scaled(xs / fs), ev.Jp * (ps / fs))
        else:
            ev = self.problem.evaluate(y * xs, lam_s * ps, self.scales)
        self.last = ev
        return ev.scaled

    def evaluate(self, X, lam, dense: bool):
        """The evaluation at X (m) and lam with its Jacobian: dense, or of the kind the continuation used."""
        if dense or self.kind == "dense":
            return self.problem.evaluate(X, lam)
        if self.kind == "sparse":
            return self.problem.evaluate_sparse(X, lam)
        return self.problem.evaluate_blocks(X, lam)

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
        opts = self.problem.options
        X = y * xs
        amps = self._accepted_amps[y.tobytes()] = self.amplitudes(y)
        q = self.q(amps[0])
        lam = lam_s * ps
        if self.last is not None:
            ev = self.last
            size = ev.JX.shape[0]
            if (len(self.evaluations) + 1) * 8 * size * size > opts.jacobian_budget_bytes:
                ev = dataclasses.replace(ev, JX=None, scaled=None)  # the Jacobian is evaluated again when needed
            self.evaluations[float(lam)] = (X, ev, amps)
        if not math.isfinite(q) or q > opts.unbounded_q:
            return (ContinuationStatus.UNBOUNDED,
                    f"q = kt X / fy = {q:.4g} exceeds {opts.unbounded_q:g} at {name} = {lam:.6g}")
        if self.last is not None:
            why = _saturation_test(self.problem, self.last, X, q, lam)
            if why is not None:
                return ContinuationStatus.UNBOUNDED, (
                    f"unbounded response (Den Hartog saturation: contact slips over the whole "
                    f"period, {why}) at {name} = {lam:.6g}, q = {q:.4g}")
        return None

    def relabel(self, res: ContinuationResult) -> ContinuationResult:
        """A corrector failure at a very large amplitude is an unbounded response; one where a part held only
        through its contacts slides as a whole (at the last evaluation) says so
        (:func:`~jointdyn.hb.results.sliding_as_a_whole`)."""
        if res.status is ContinuationStatus.FAILED and res.y.shape[0] > 0:
            q = self.q(self.amplitudes(res.y[-1])[0])
            if q > self.problem.options.unbounded_fail_fraction * self.problem.options.unbounded_q:
                return dataclasses.replace(
                    res, status=ContinuationStatus.UNBOUNDED,
                    message=f"Newton failed with q = {q:.4g} growing: unbounded response ({res.message})")
        if res.status is ContinuationStatus.FAILED and self.last is not None and self.problem.restart_at_reference:
            why = sliding_as_a_whole(self.problem, self.last.JX)
            if why:
                return dataclasses.replace(res, message=res.message + why)
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


def _forcing_problem(system: System, gamma: float, harmonics: int, samples: int, condense,
                     options: HBOptions | None = None):
    """The problem at this gamma with the forcing amplitude as its (fixed) parameter."""
    return make_problem(system, condense=condense, harmonics=harmonics, samples=samples, parameter="f1",
                        gamma=gamma, options=options)


def solve_point(problem: HBProblem, gamma: float, guess, tol: float, max_iter: int):
    """(X (m), converged, iterations): harmonic balance at one point by damped Newton.

    ``problem`` has the forcing amplitude as its parameter, fixed at its
    reference value, at ``gamma`` (:func:`_forcing_problem`). Newton starts
    from ``guess`` (m; default the stuck-contact linear solution); where it
    fails from the linear solution, the forcing amplitude is continued from
    ``HBOptions.homotopy_start`` F1 to F1 at this gamma, where the
    stuck-contact linear solution is a good start (:func:`_homotopy`), and
    Newton is made again from its end.
    """
    f1 = problem.f1_ref
    xs, fs, _ = _scales(problem, f1)

    def residual(y, lam):
        ev = problem.evaluate(y * xs, f1)
        return ev.R / fs, ev.JX * (xs / fs), ev.Jp / fs

    y0 = (problem.linear_guess(f1) if guess is None else guess) / xs
    if y0.size != problem.size:
        raise ValueError(f"guess must have length {problem.size}, got {y0.size}")
    y, ok, it = newton(residual, y0, 0.0, tol=tol, max_iter=max_iter)
    if not ok and guess is None and f1 > 0:
        # homotopy: continue in the forcing amplitude from a weak force,
        # where the stuck-contact linear solution is a good start
        X = _homotopy(problem, gamma, tol)
        if X is not None:
            y, ok, it = newton(residual, X / xs, 0.0, tol=tol, max_iter=max_iter)
    return y * xs, ok, it


def _homotopy(problem: HBProblem, gamma: float, tol: float):
    """X (m) at the full forcing amplitude F1 of ``problem``, continued in the forcing amplitude from
    ``HBOptions.homotopy_start`` F1 at the same gamma and discretisation (None where the branch does not
    reach F1); the request :func:`jointdyn.hb.continue_hb` makes with ``parameter="f1"``."""
    system, f1 = problem.system, problem.f1_ref
    opt = make_options(None, {"tol": tol})
    if opt.start_extrapolation is None and all(c.law.smooth_force for c in system.contacts):
        opt = dataclasses.replace(opt, start_extrapolation=START_EXTRAPOLATION)
    req = _Request(system=system, start=problem.options.homotopy_start * f1, stop=f1, parameter=F1, gamma=gamma,
                   max_step=None, dof=system.response_dof, options=opt, backward=False, progress=False,
                   condense=problem.condensed, hb=problem.options)
    br = continued_branch(req, Level(problem.H, problem.Ns))
    lam = br.parts.lam
    if br.status is ContinuationStatus.COMPLETE and lam.size and lam[-1] == f1:
        return br.parts.X[-1]
    return None


def _segment(tr: _Tracker, lam_a, lam_b, opt: ContinuationOptions, progress, monitor=None) -> ContinuationResult:
    """One continued segment from lam_a to lam_b (the start from the stuck linear solution, or, where Newton
    fails from it in gamma, from :func:`solve_point`); ``monitor`` defaults to the tracker's."""
    problem = tr.problem
    xs, _, ps = tr.scales
    with _bar(lam_a / ps, lam_b / ps, f"HB {problem.parameter.name}", progress, problem.parameter.name, ps) as bar:
        y0 = problem.linear_guess(lam_a) / xs
        if (problem.parameter is GAMMA
                and not newton(tr.residual, y0, lam_a / ps, opt, max_iter=problem.options.start_max_iter)[1]):
            # start by a homotopy in the forcing amplitude at this gamma
            # when Newton from the stuck-contact solution fails
            X, ok, _ = solve_point(_forcing_problem(problem.system, lam_a, problem.H, problem.Ns, problem.condensed,
                                                    problem.options),
                                   lam_a, None, opt.tol, problem.options.solve_max_iter)
            if ok:
                y0 = X / xs
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


def continued_branch(req: _Request, level: Level, watch_for=None):
    """The branch at ``level`` (a :class:`~jointdyn.hb.levels.Level`): a :class:`_Draft`; with
    ``watch_for(tracker, options)`` (a monitor of the continuation with a ``target``, None until it asks
    to stop, and a ``restart()`` for the segment continued back), that target where it stopped the branch
    (:class:`jointdyn.hb.discretisation._PeakWatch`)."""
    problem = make_problem(req.system, condense=req.condense, response_dofs=(req.dof,), harmonics=level.harmonics,
                           samples=level.samples, parameter=req.parameter, gamma=req.gamma, options=req.hb)
    with preconditioned_by(problem.block_preconditioner()):
        return _continued(req, problem, watch_for)


def _continued(req: _Request, problem: HBProblem, watch_for):
    """:func:`continued_branch` of its problem."""
    tr = _Tracker(problem, _scales(problem, req.start), req.dof, req.stability, req.progress)
    opt = req.options
    if req.max_step is not None:
        opt = dataclasses.replace(opt, max_dlam=req.max_step / tr.scales[2])
    watch = watch_for(tr, opt) if watch_for is not None else None
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
    joined = dataclasses.replace(joined, fold=_turning_mask(joined.lam, logq, joined.segment, joined.gap, start, stop,
                                                                      tr.problem.options))
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
    prominence = tr.problem.options.peak_prominence
    return [_refined_peak(tr, res, g, i, segment, opt) for i in local_maxima(g, res.gap, prominence)]


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


def _turning_mask(lam, observed, segment, gap, start, stop, opts: HBOptions):
    """Folds: points where the parameter is extremal along a segment, beyond a dead band.

    A reversal of the parameter counts once it exceeds
    ``opts.turning_band`` of the range, or once log q has moved by
    more than ``opts.turning_band_log_q`` while the parameter is still
    short of the extreme (a fold whose two branches are close in the
    parameter but far apart in amplitude). The jitter of points at a
    non-smooth corner (onset of slip or separation, where the branch keeps
    going) is within both bands and does not count.
    """
    m = np.zeros(lam.size, dtype=bool)
    band = opts.turning_band * abs(stop - start)
    for sgm in np.unique(segment):
        idx = np.flatnonzero(segment == sgm)
        tp = turning_points(lam[idx], gap[idx], band=band, observed=observed[idx],
                            observed_band=opts.turning_band_log_q)
        m[idx[tp]] = True
    return m
