"""What a harmonic-balance computation is asked apart from its system and its range: :class:`HBOptions`
(every number of harmonic balance's own, with its default).

The step control of the continuation is :class:`~jointdyn.continuation.ContinuationOptions`, the
stability of the points :class:`~jointdyn.hb.stability_options.StabilityOptions`; the numbers harmonic
balance shares with other packages stay in ``config`` (the default discretisation, the tolerance of
the automatic choice ``config.HB_AUTO_RTOL``, the sizes of the large-solve paths)."""

from __future__ import annotations

from dataclasses import dataclass

from .. import _validate as V

__all__ = ["HBOptions", "hb_options"]


@dataclass(frozen=True)
class HBOptions:
    """Harmonic balance's own numbers: the Jacobian's form, the automatic discretisation, the Newton
    iterations, the end of a branch, its folds and peaks, the memory it keeps and the condensation.

    ``q = kt X / fy`` is the amplitude relative to the first contact's slip amplitude
    (:func:`~jointdyn.hb.problem.reference_scales`).

    Attributes
    ----------
    dense_max_unknowns : int
        A branch of a (full) problem with at most this many unknowns n (2H+1) is continued with dense
        Jacobians; beyond, by the large-problem path (:meth:`~jointdyn.hb.problem.HBProblem.large_jacobian`:
        sparse, or harmonic blocks for a structure dense on its DOFs). Stability is chosen apart, by
        :class:`~jointdyn.hb.stability_options.StabilityOptions` (default 2000; >= 0).
    block_preconditioner : bool
        From ``config.CONT_KRYLOV_SOLVE`` unknowns, HB and EPMC Newton and tangent solves are GMRES
        preconditioned by per-harmonic factorisations of the Jacobian's diagonal harmonic blocks
        (:mod:`jointdyn.hb._precond`); False: the direct path (one LU of the bordered matrix, reused
        through GMRES), the reference of ``benchmarks/bench_hb_scale.py`` (default True).
    auto_early_drop : float
        While the first branch of an automatic choice is continued, its highest point so far is
        checked once the amplitude has fallen below this fraction of it (a resonance passed); where
        that peak converges at a finer level, the branch stops there and is computed at that level,
        and the finished branch must confirm the stop (default 0.5; in (0, 1]).
    auto_max_harmonics, auto_max_samples : int
        The largest H and Ns an automatic choice takes (the check solves go one level beyond); with
        separation the samples decide, H = 7 already within 2e-4 of H = 15 on the paper's grid
        (defaults 15 and 2048; >= 1 and >= 4).
    start_max_iter : int
        Newton iterations of the start of a branch from the stuck linear solution (default 30).
    solve_max_iter : int
        Newton iterations of a single solution, where :func:`~jointdyn.hb.harmonic_balance` is given no
        ``max_iter`` (default 50).
    homotopy_start : float
        A homotopy in the forcing amplitude starts at this fraction of F1 (default 1e-3; in (0, 1)).
    unbounded_q : float
        A response is declared unbounded when q exceeds this, a hard bound (default 1e5).
    unbounded_fail_fraction : float
        ... or when the corrector fails at the smallest step with q above this fraction of
        ``unbounded_q`` (default 0.1; in (0, 1]).
    saturation_q : float
        The describing-function saturation test (Den Hartog; C = 0, single DOF) applies once q exceeds
        this (default 30).
    saturation_slip_fraction : float
        ... and the contact slips at least this fraction of the period (default 0.9; in (0, 1]).
    turning_band : float
        Turning points (folds) of a branch: the parameter must come back by more than this fraction of
        the range, or log q move by more than ``turning_band_log_q`` while the parameter is short of its
        extreme (a fold whose branches are close in the parameter); the jitter of points at a non-smooth
        corner stays within both (default 5e-4).
    turning_band_log_q : float
        See ``turning_band`` (default 5e-3).
    fold_window : int
        A turning point is a fold only with an unstable point between it and the neighbouring turning
        points (without one on a side: within this many points): a saddle-node changes the number of
        unstable multipliers (default 3).
    peak_prominence : float
        A local maximum of the amplitude along a branch is a peak when the amplitude falls by more than
        this fraction of it on both sides, before rising above it again (default 1e-3; in [0, 1)).
    jacobian_budget_bytes : int
        Bytes of dense Jacobians a branch keeps at once: the continuation monitor keeps the evaluations
        of accepted points with their Jacobians while they fit (beyond, without: the point is evaluated
        again for its stability), and Hill's method runs on chunks of points that fit (default 2**28,
        256 MiB; >= 1).
    max_gamma_step : float
        Largest gamma spacing of a branch in gamma when the caller gives no ``max_step`` (the command
        line passes the STEP of ``--gamma``). The chord bound ``CONT_CHORD_TOL`` is a distance in
        (gamma, ln amplitude); on a steep flank a chord within it can still miss the amplitude at the
        same gamma by more than 1 % (1.4 % at 0.1 gamma spacing on the Jenkins benchmark branch,
        F1 = 5 N, docs/hb-comparison.md); 0.02 keeps it below 1 % (0.9 %) for about 25 % more points
        (default 0.02).
    condense_min_dofs : int
        The automatic choice condenses onto the contact DOFs (:mod:`jointdyn.hb.condense`) systems of at
        least this many DOFs (default 12; >= 1) ...
    condense_max_fraction : float
        ... whose retained DOFs (contacts, DOF 0, response DOFs) are at most this fraction of all DOFs
        (default 0.5; in (0, 1]). The DOFs even where the condensed problem keeps fewer relative
        coordinates (``condense_relative``): on the shipped lap joint (362 coordinates of 733 DOFs) the
        condensed branch took about twice the CPU seconds of the full problem's harmonic blocks
        (docs/performance.md), so the automatic choice leaves it to them.
    condense_relative : bool
        A condensed problem keeps relative coordinates (a contact's selection row, a node pair's
        ``x_a - x_b``: three unknowns per pair and harmonic instead of six) where they are fewer than the
        retained DOFs and independent, else the DOFs (default True; False: always the DOFs;
        :mod:`jointdyn.hb._coordinates`).
    """

    dense_max_unknowns: int = 2000
    block_preconditioner: bool = True
    auto_early_drop: float = 0.5
    auto_max_harmonics: int = 15
    auto_max_samples: int = 2048
    start_max_iter: int = 30
    solve_max_iter: int = 50
    homotopy_start: float = 1e-3
    unbounded_q: float = 1e5
    unbounded_fail_fraction: float = 0.1
    saturation_q: float = 30.0
    saturation_slip_fraction: float = 0.9
    turning_band: float = 5e-4
    turning_band_log_q: float = 5e-3
    fold_window: int = 3
    peak_prominence: float = 1e-3
    jacobian_budget_bytes: int = 2**28
    max_gamma_step: float = 0.02
    condense_min_dofs: int = 12
    condense_max_fraction: float = 0.5
    condense_relative: bool = True

    def __post_init__(self) -> None:
        ints = {"dense_max_unknowns": 0, "auto_max_harmonics": 1, "auto_max_samples": 4, "start_max_iter": 1,
                "solve_max_iter": 1, "fold_window": 1, "jacobian_budget_bytes": 1, "condense_min_dofs": 1}
        for name, least in ints.items():
            object.__setattr__(self, name, V.positive_int(name, getattr(self, name), least))
        for name in ("block_preconditioner", "condense_relative"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name} must be True or False, got {getattr(self, name)!r}")
        for name in ("auto_early_drop", "unbounded_fail_fraction", "saturation_slip_fraction",
                     "condense_max_fraction"):
            object.__setattr__(self, name, V.in_range(name, getattr(self, name), 0.0, 1.0, lo_open=True))
        object.__setattr__(self, "homotopy_start",
                           V.in_range("homotopy_start", self.homotopy_start, 0.0, 1.0, lo_open=True, hi_open=True))
        object.__setattr__(self, "peak_prominence",
                           V.in_range("peak_prominence", self.peak_prominence, 0.0, 1.0, hi_open=True))
        for name in ("unbounded_q", "saturation_q", "turning_band", "turning_band_log_q", "max_gamma_step"):
            object.__setattr__(self, name, V.positive(name, getattr(self, name)))


def hb_options(value) -> HBOptions:
    """``value`` as HBOptions: None (the defaults) or HBOptions (ValueError naming ``hb_options`` otherwise)."""
    if value is None:
        return HBOptions()
    if not isinstance(value, HBOptions):
        raise ValueError(f"hb_options must be an HBOptions or None (the defaults), got {value!r}")
    return value
