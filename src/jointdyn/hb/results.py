"""What harmonic balance returns: the branch, its peaks, the per-point status, the check of the
discretisation and the solution at one point.

Frozen dataclasses built by :mod:`jointdyn.hb.branch` (a branch at a fixed
discretisation), :mod:`jointdyn.hb.discretisation` (the automatic choice of
harmonics and samples) and :mod:`jointdyn.hb.frc` (the entry points).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import config
from ..continuation import ContinuationStatus
from ..status import Status
from ..systems import free_modes
from .parameters import GAMMA
from .problem import HBProblem, stuck_stiffness

__all__ = ["JOINED", "DiscretisationCheck", "HBBranch", "HBPeak", "HBSolution", "PointStatus", "SolveStatus"]


class PointStatus(Status):
    """How a point of a harmonic-balance branch joins the point before it (Dataset ``point_status``)."""

    START = "start", "first point of a segment: not joined to the point before it", True
    JOINED = "joined", "joined to the previous point along the branch", True
    CORNER = "corner", ("joined to the previous point past a sharp corner of the branch (found at fixed "
                        "parameter; the curve is continuous)"), True
    AFTER_JUMP = "after-jump", ("reached by a jump over a discontinuity of the contact force: not joined to the "
                                "previous point")
    STOPPED = "stopped", "last point of a segment that stopped short (the branch message says where and why)"


#: point statuses joined to the point before them: a branch is drawn as one line per run of them
#: (:func:`jointdyn.figures.curves.branch_pieces`)
JOINED = (PointStatus.JOINED.value, PointStatus.CORNER.value)

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
    stability : str
        How ``growth`` was computed: ``hill`` (every eigenvalue of Hill's
        companion matrix), ``hill-arnoldi`` (the exponents nearest the
        imaginary axis by shift-invert Arnoldi) or ``not-computed``
        (asked for no stability: growth NaN, no point stable).
    stability_checked : ndarray of bool (points,)
        Where the label ``stable`` was computed
        (``StabilityOptions.check_every``,
        :mod:`jointdyn.hb.stability_schedule`); elsewhere it is carried over
        from the checked points on both sides, which agree, and ``growth``
        is NaN. None when built: the points with a finite growth.
    stability_check_every : int
        ``StabilityOptions.check_every`` of the branch (1: every point).
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
    stability: str = "hill"
    stability_checked: np.ndarray | None = None
    stability_check_every: int = 1

    def __post_init__(self) -> None:
        if self.stability_checked is None:
            object.__setattr__(self, "stability_checked", np.isfinite(np.asarray(self.growth, dtype=float)))

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


class SolveStatus(Status):
    """Outcome of a harmonic-balance solve at one point (:attr:`HBSolution.status`)."""

    CONVERGED = "converged", "Newton converged: the scaled residual is within the tolerance", True
    NOT_CONVERGED = "not-converged", ("Newton did not converge within its iterations: the last iterate is "
                                      "returned, not a solution")


@dataclass(frozen=True)
class HBSolution:
    """One harmonic-balance solution at fixed parameters (built by :func:`harmonic_balance`).

    Attributes
    ----------
    problem : HBProblem
    X : ndarray
        Harmonic coefficients (harmonic-major), m.
    status : SolveStatus
        ``converged`` (``status.ok``) or ``not-converged``.
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
    status: SolveStatus
    iterations: int
    residual_norm: float
    amplitude_m: float
    offset_m: float
    max_abs_m: float
    stable: bool
    growth: float
    multipliers: np.ndarray
    aft_info: np.ndarray

    @property
    def message(self) -> str:
        """The status's message, with the residual and the iterations (and, where Newton failed on a part held
        only through its contacts that slides as a whole, that: :func:`sliding_as_a_whole`)."""
        out = f"{self.status.message} (max |R| = {self.residual_norm:.4g} N after {self.iterations} iterations)"
        if not self.status.ok and self.problem.restart_at_reference:
            out += sliding_as_a_whole(self.problem, self.problem.evaluate(self.X, self.problem.f1_ref).JX)
        return out


#: |dR/dX v| / |K_stuck v| below which a rigid-body mode v of K_reference is not held by the contacts
_NOT_HELD_RTOL = 1e-8


def sliding_as_a_whole(problem: HBProblem, JX) -> str:
    """``"; ..."`` saying that the part slides as a whole, or ``""``.

    For a problem held only through its contacts
    (:attr:`HBProblem.restart_at_reference`, full unknowns): where the
    static harmonic's Jacobian ``JX`` (dense, N/m) along a rigid-body mode v
    of ``System.K_reference`` (less its part along the rigid-body modes of the
    whole, for a free-free structure) is below ``_NOT_HELD_RTOL`` of the stuck
    structure's ``K_stuck v``, no contact resists a shift of the part: every
    one of its contacts slips every cycle (macroslip), the
    part's mean position is not unique, and Newton fails on a singular
    matrix. That is the physics of the part, not a failure of the method.
    (A Jenkins element that sticks only at the reversals is such a
    contact too: each slip forgets where the last one ended.)
    """
    if (not problem.restart_at_reference or problem.condensed or not isinstance(JX, np.ndarray)
            or JX.shape[0] != problem.size or problem.system.ndof > config.SYSTEM_DENSE_CHECK_MAX_DOF
            or not np.all(np.isfinite(JX))):
        return ""
    K = problem.system.K_reference
    lam, vec = np.linalg.eigh(0.5 * (K + K.T))
    Ks = stuck_stiffness(problem.system)
    free, M = free_modes(problem.system), problem.system.M
    for j in np.flatnonzero(lam <= config.SYSTEM_RIGID_MODE_RTOL * abs(lam[-1])):
        # of a free-free structure, the motion of the parts relative to each other: the whole's rigid-body
        # modes (gauged on harmonic 0) taken out
        v = vec[:, j] - free @ (free.T @ (M @ vec[:, j]))
        if not np.linalg.norm(v) > 1e-6:
            continue
        held = float(np.linalg.norm(JX[:, :problem.n] @ v))
        if held <= _NOT_HELD_RTOL * float(np.linalg.norm(Ks @ v)):
            dof = int(np.argmax(np.abs(v)))
            return (f"; the part held only through its contacts (mostly DOF {dof}) slides as a whole there: its "
                    "contacts slip every cycle (macroslip) and resist no shift of it, so its mean position is "
                    "not unique (the static harmonic is singular): the physics of the part, not a failure of the "
                    "method")
    return ""
