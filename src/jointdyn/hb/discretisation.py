"""The automatic choice of harmonics and samples of a harmonic-balance branch.

A branch is computed at a first level (H, Ns); every refined peak is solved
again with more harmonics and with more samples, and where its amplitude
changes by more than ``config.HB_AUTO_RTOL`` the branch is computed again
at the level the peaks ask for (:func:`adaptive_branch`). While the first
branch is continued, a passed resonance that already asks for a finer level
stops it (:class:`_PeakWatch`). Each branch at a fixed level is
:func:`jointdyn.hb.branch.continued_branch`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import config
from ..continuation import ContinuationOptions, ContinuationStatus, newton, refine_maximum, stage_note
from .branch import _Request, _scales, _Tracker, continued_branch
from .condense import make_problem
from .levels import Discretisation, Level
from .options import HBOptions, hb_options
from .results import DiscretisationCheck, HBBranch, HBPeak

def _fixed_branch(req: _Request, level: Level, disc: Discretisation | None = None, watch: bool = False):
    """The branch at ``level``: a :class:`~jointdyn.hb.branch._Draft`,
    or, with ``watch``, a :class:`_Refine` where a peak asked for a finer level while the branch was continued
    (``disc``: which of the harmonics and the samples may change; :class:`_PeakWatch`)."""
    watch_for = (lambda tr, opt: _PeakWatch(tr, req, level, disc, opt)) \
        if watch and disc is not None and (disc.harmonics_auto or disc.samples_auto) else None
    if disc is not None and (disc.harmonics_auto or disc.samples_auto):
        k, most = level_number(level, disc, req.hb)
        stage_note(f"HB level {k}/{most}: H = {level.harmonics}, Ns = {level.samples}", req.progress)
    return continued_branch(req, level, watch_for)


def _doublings(a: int, b: int, grow) -> int:
    """How many times ``grow`` is applied to a before it reaches b (0 when a >= b)."""
    n = 0
    while a < b:
        a, n = grow(a), n + 1
    return n


def level_number(level: Level, disc: Discretisation, options: HBOptions | None = None) -> tuple[int, int]:
    """(k, most): ``level`` is the k-th of an automatic choice from ``disc.first``, which has at most ``most``
    (each raise of the harmonics H -> 2H + 1 and of the samples Ns -> 2 Ns within
    ``options.auto_max_harmonics`` and ``options.auto_max_samples`` (:class:`~jointdyn.hb.options.HBOptions`,
    None: the defaults) is one level; a samples retry after a failure is one too)."""
    opts = hb_options(options)
    (h0, s0), grow_h, grow_s = disc.first, (lambda h: 2 * h + 1), (lambda s: 2 * s)
    k = 1 + _doublings(h0, level.harmonics, grow_h) + _doublings(s0, level.samples, grow_s)
    most = 1 + (_doublings(h0, opts.auto_max_harmonics + 1, grow_h) - 1 if disc.harmonics_auto else 0) \
        + (_doublings(s0, opts.auto_max_samples + 1, grow_s) - 1 if disc.samples_auto else 0)
    return k, max(k, most)


def check_levels(level: Level, disc: Discretisation):
    """The :class:`Level` of the harmonics check and of the samples check one level above ``level``
    (None: not made)."""
    H, Ns = level
    h2 = 2 * H + 1
    by_h = Level(h2, max(Ns, 2 * h2 + 2) if disc.samples_auto else Ns) if disc.harmonics_auto else None
    if by_h is not None and by_h.samples < 2 * h2 + 2:
        by_h = None  # the samples fixed by the caller cannot carry more harmonics
    return by_h, (Level(H, 2 * Ns) if disc.samples_auto else None)


def next_level(level: Level, disc: Discretisation, bad_h: bool, bad_s: bool,
               options: HBOptions | None = None) -> Level:
    """The level the checks ask for, within ``options.auto_max_harmonics`` and ``options.auto_max_samples``
    (:class:`~jointdyn.hb.options.HBOptions`, None: the defaults; equal to ``level``: no refinement).

    The samples first: with too few, the sampling error of the contact
    force also moves the solution with more harmonics, so H is raised
    only once the samples pass their check.
    """
    opts = hb_options(options)
    by_h, by_s = check_levels(level, disc)
    if bad_s and by_s is not None:
        return by_s if by_s.samples <= opts.auto_max_samples else level
    if bad_h and by_h is not None and by_h.harmonics <= opts.auto_max_harmonics:
        return by_h
    return level


def _at_level(req: _Request, condensed: bool, X, level: Level):
    """(tracker of the problem at ``level``, the harmonics X there in its scaled unknowns, zero above
    their H)."""
    problem = make_problem(req.system, condense=condensed, response_dofs=(req.dof,), harmonics=level.harmonics,
                           samples=level.samples, parameter=req.parameter, gamma=req.gamma, options=req.hb)
    tr = _Tracker(problem, _scales(problem, req.start), req.dof, req.stability, req.progress)
    Xm = np.asarray(X).reshape(-1, problem.n)
    X0 = np.zeros((problem.nh, problem.n))
    X0[: min(Xm.shape[0], problem.nh)] = Xm[: problem.nh]
    return tr, X0.ravel() / tr.scales[0]


def _solve_at(req: _Request, condensed: bool, lam: float, X, level: Level):
    """(amplitude of the response DOF (m; NaN where Newton failed), X) at parameter ``lam`` at
    ``level``, by Newton from the harmonics X (zero above their H)."""
    tr, y0 = _at_level(req, condensed, X, level)
    xs, _, ps = tr.scales
    y, ok, _ = newton(tr.residual, y0, lam / ps, req.options)
    return (tr.amplitudes(y)[0] if ok else math.nan), y * xs


def _first_step_amplitude(req: _Request, condensed: bool, lam: float, X, level: Level) -> float:
    """Amplitude of the response DOF (m) after one Newton step from the harmonics X at parameter
    ``lam`` at ``level``: the solution's amplitude there to first order in the change
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


def _peak_level(req: _Request, condensed: bool, pk: HBPeak, scale: float, level, disc):
    """(level at which the peak converges (or the bound), (harmonics change, samples change) at ``level``).

    The peak is solved with more harmonics and with more samples
    (:func:`check_levels`); the changes are relative to ``scale`` (the
    highest peak of the branch, so that a small secondary peak asks for no
    more than its share of the curve). Where a change exceeds
    ``config.HB_AUTO_RTOL`` the peak is solved at the refined level and
    checked there again.
    """
    return _peak_levels(req, condensed, pk, scale, level, disc)[:2]


def _peak_levels(req: _Request, condensed: bool, pk, scale: float, level, disc):
    """:func:`_peak_level`, and whether the peak's check passed at the level returned (not at a bound)."""
    at, X, amp, first = level, pk.X, pk.amplitude_m, None
    while True:
        solved = {lv: _solve_at(req, condensed, pk.lam, X, lv) for lv in check_levels(at, disc) if lv}
        ch = tuple(_change(solved[lv][0], amp, scale) if lv else math.nan for lv in check_levels(at, disc))
        first = ch if first is None else first
        nxt = next_level(at, disc, ch[0] > config.HB_AUTO_RTOL, ch[1] > config.HB_AUTO_RTOL, req.hb)
        if nxt == at:
            return at, first, not (ch[0] > config.HB_AUTO_RTOL or ch[1] > config.HB_AUTO_RTOL)
        amp, X = solved[nxt] if nxt in solved else _solve_at(req, condensed, pk.lam, X, nxt)
        at = nxt
        if not math.isfinite(amp):
            return at, first, False


def _combined_target(req: _Request, condensed: bool, peaks, scale: float, level, disc, wanted):
    """The level of the next branch: the most harmonics and the most samples that the peaks ask for
    (``wanted``: their levels from :func:`_peak_level`).

    Where the peaks ask for both more harmonics and more samples, the
    harmonics are checked again at the higher samples first (the peaks
    solved there): a harmonics check made with too few samples also
    measures the sampling error of the contact force, and more harmonics
    cost as much as more samples in every AFT evaluation of the branch.
    """
    target = Level(max([level.harmonics] + [w.harmonics for w in wanted]),
                   max([level.samples] + [w.samples for w in wanted]))
    if not (target.harmonics > level.harmonics and target.samples > level.samples):
        return target
    at = Level(level.harmonics, target.samples)
    again = []
    for pk in peaks:
        amp, X = _solve_at(req, condensed, pk.lam, pk.X, at)
        if not math.isfinite(amp):
            return target
        again.append(_peak_level(req, condensed, dataclasses.replace(pk, X=X, amplitude_m=amp),
                                 scale, at, disc)[0])
    return Level(max([at.harmonics] + [w.harmonics for w in again]), max([at.samples] + [w.samples for w in again]))


@dataclass(frozen=True)
class _Refine:
    """What :func:`_fixed_branch` returns where a peak asked for a finer level during the continuation:
    that level, the peak (a :class:`_Candidate`) and the level of the branch it stopped."""

    level: Level
    peak: _Candidate = dataclasses.field(repr=False)
    stopped: Level


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
    amplitude has fallen below ``HBOptions.auto_early_drop`` times its
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
    :func:`adaptive_branch` keeps a stop only where the finished branch is
    converged and the peak asks for the same level relative to the
    finished branch's highest peak (:func:`_confirmed`). The finished
    branch's peaks are checked again, so a branch that passes here can
    still be refined.
    """

    def __init__(self, tr: _Tracker, req: _Request, level, disc, opt: ContinuationOptions):
        self.tr, self.req, self.level, self.disc, self.opt = tr, req, level, disc, opt
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
        if self.top is None or g >= pts[self.top][0] + math.log(self.req.hb.auto_early_drop):
            return None
        i, self.top = self.top, None
        self.checked = pts[i][0]
        return self._check(i)

    def _check(self, i: int):
        tr = self.tr
        xs, _, ps = tr.scales
        g, lam_s, y = self.points[i]
        condensed = tr.problem.condensed
        by_h, by_s = check_levels(self.level, self.disc)
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
        target, converged = _peak_target(self.req, condensed, pk, pk.amplitude_m, self.level, self.disc)
        if not converged or target == self.level:
            return None  # the finished branch decides
        self.target = _Refine(target, pk, self.level)
        name = tr.problem.parameter.name
        return ContinuationStatus.STOPPED, (f"the peak near {name} = {pk.lam:.6g} asks for "
                                            f"H = {target.harmonics}, Ns = {target.samples}")


def _peak_target(req: _Request, condensed: bool, pk, scale: float, level, disc):
    """(the level the peak alone asks for, checked from ``level`` with its changes relative to
    ``scale``; whether its check passed there)."""
    wanted, _, converged = _peak_levels(req, condensed, pk, scale, level, disc)
    return _combined_target(req, condensed, [pk], scale, level, disc, [wanted]), converged


def _confirmed(req: _Request, condensed: bool, stop: _Refine, scale: float, disc) -> bool:
    """Whether the peak that stopped a branch asks for the same level with its changes relative to
    ``scale`` (the highest peak of the finished branch) as relative to its own amplitude."""
    return _peak_target(req, condensed, stop.peak, scale, stop.stopped, disc) == (stop.level, True)


def _watched_branch(req: _Request, level, disc, levels, retry_failed: bool, watch: bool):
    """(branch, its level, the :class:`_Refine` of a stop or None): :func:`_fixed_branch` at ``level``
    (with ``watch``, watched by a :class:`_PeakWatch`), computed again at the level a peak asks for where
    one stops it, and with twice the samples where a branch asked for fails (after a stop by a peak, or
    where ``retry_failed``: a finer level may fail where the coarser went on, because a closed form's
    force jumps with the normal load and Newton fails at one sampling and not at the next). Each further
    level is appended to ``levels``."""
    br = _fixed_branch(req, level, disc, watch=watch)
    stop = None
    if isinstance(br, _Refine):
        stop = br
        level, retry_failed = stop.level, True
        levels.append(level)
        br = _fixed_branch(req, level, disc)
    while retry_failed and br.status is ContinuationStatus.FAILED and disc.samples_auto \
            and 2 * level.samples <= req.hb.auto_max_samples:
        level = Level(level.harmonics, 2 * level.samples)
        levels.append(level)
        br = _fixed_branch(req, level, disc)
    return br, level, stop


def _worst(values) -> float:
    """Largest of the values that are not NaN (NaN when there is none)."""
    v = [x for x in values if not math.isnan(x)]
    return max(v) if v else math.nan


def adaptive_branch(req: _Request, disc: Discretisation, watch: bool = True) -> HBBranch:
    """The branch at the first level of ``disc``, computed again at a finer level while its peaks ask for
    one (where ``disc`` lets the harmonics or the samples change); with its :class:`DiscretisationCheck`.

    With ``watch``, the first branch stops at a passed resonance that asks
    for a finer level (:class:`_PeakWatch`); where the finished branch does
    not confirm such a stop (it is not converged, or the peak asks for
    another level relative to the finished branch's highest peak: the stop
    was made at a resonance lower than one found later), the whole choice
    is made again without stops.
    """
    level = disc.first
    levels = [level]
    if not (disc.harmonics_auto or disc.samples_auto):
        return _fixed_branch(req, level).branch()
    br, level, stop = _watched_branch(req, level, disc, levels, False, watch)
    while True:
        scale = max([pk.amplitude_m for pk in br.peaks], default=0.0)
        checks = [_peak_level(req, br.problem.condensed, pk, scale, level, disc) for pk in br.peaks]
        target = _combined_target(req, br.problem.condensed, br.peaks, scale, level, disc, [c[0] for c in checks])
        if target == level:
            break
        levels.append(target)
        br, level, _ = _watched_branch(req, target, disc, levels, br.status is not ContinuationStatus.FAILED, False)
    by_h, by_s = check_levels(level, disc)
    ch_h, ch_s = _worst(c[1][0] for c in checks), _worst(c[1][1] for c in checks)
    converged = not (ch_h > config.HB_AUTO_RTOL or ch_s > config.HB_AUTO_RTOL)
    if stop is not None and not (converged and _confirmed(req, br.problem.condensed, stop, scale, disc)):
        return adaptive_branch(req, disc, watch=False)
    check = DiscretisationCheck(harmonics_auto=disc.harmonics_auto, samples_auto=disc.samples_auto,
                                levels=tuple(levels), check_harmonics=by_h.harmonics if by_h else 0,
                                check_samples=by_s.samples if by_s else 0,
                                harmonics_change=ch_h, samples_change=ch_s, peaks=len(checks),
                                rtol=config.HB_AUTO_RTOL, converged=converged)
    br = br.branch()
    message = br.message
    if not converged:
        message += (f"; the peak amplitude is not converged in the discretisation at its bound "
                    f"(H = {level.harmonics}, Ns = {level.samples}): it changes by "
                    f"{100 * _worst([ch_h, ch_s]):.3g} % with {check.check_harmonics or level.harmonics} "
                    f"harmonics or {check.check_samples or level.samples} samples "
                    f"(tolerance {100 * config.HB_AUTO_RTOL:g} %)")
    return dataclasses.replace(br, discretisation=check, message=message)
