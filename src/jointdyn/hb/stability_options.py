"""What the stability of a harmonic-balance branch is asked: :class:`StabilityOptions` (every number of it)."""

from __future__ import annotations

from dataclasses import dataclass

from .. import _validate as V

__all__ = ["StabilityOptions", "STABILITY_METHODS"]

#: how the Floquet exponents are computed: "auto" (by size), "dense" (every eigenvalue of Hill's companion
#: matrix, :mod:`jointdyn.hb.stability`), "arnoldi" (those nearest the imaginary axis,
#: :mod:`jointdyn.hb.hill_arnoldi`), "none" (not computed: growth NaN, the Dataset says ``not-computed``)
STABILITY_METHODS = ("auto", "dense", "arnoldi", "none")


@dataclass(frozen=True)
class StabilityOptions:
    """How the Floquet exponents of harmonic-balance solutions are computed.

    Attributes
    ----------
    method : {"auto", "dense", "arnoldi", "none"}
        ``auto`` (default): dense Hill up to ``dense_max_rows`` companion
        rows, shift-invert Arnoldi beyond; ``none``: no stability (the
        growth is NaN and the branch says ``not-computed``).
    dense_max_rows : int
        Largest companion matrix (2 n (2H+1) rows, n the DOFs of the full
        structure) for which ``auto`` takes the dense method. Measured on the
        scalar-contact chain of ``benchmarks/bench_hb_stability.py`` (H = 3,
        one BLAS thread, a 2-core machine at a load of 4-5) per point: with
        Q(sigma) factorised as a dense matrix (a dense Jacobian), dense Hill
        and Arnoldi took about the same at 420-504 rows (0.06-0.17 s both)
        and dense was 1.8-2x slower at 588 rows; with the chain's sparse
        Jacobian (SuperLU), dense Hill was 17x faster at 294 rows (0.012
        against 0.208 s, its compiled path) and 3.4x slower at 588 rows
        (0.094 against 0.028 s), 12x at 1722 and 42x at 4410 rows.
    arnoldi_shifts : int
        Shifts on the imaginary axis between 0 and i w/2, both included
        (>= 1, default 3: 0, i w/4, i w/2); more shifts cover a wider band
        about the axis with the same eigenvalues per shift. 1: the real
        shift 0 alone (a real LU, about a quarter of a complex one's), with
        the shifts of ``arnoldi_cover_shifts`` added where its disk does not
        reach i w/2 (:mod:`jointdyn.hb.hill_arnoldi`). On the lap joint at
        H = 3 (5131 rows, one BLAS thread, load about 8-11) one shift took
        3.5-5.0 s of CPU per point against 35-38 s for three, with the same
        exponents (docs/performance.md). Not the default: on the tests'
        condensed models one shift misses an exponent outside the strip
        that dense Hill's selection keeps (an undamped model) and two shifts
        (0, i w/2) give growths off dense Hill's by more than 1e-6 on a
        condensed branch (docs/harmonic-balance.md).
    arnoldi_cover_shifts : int
        Shifts between 0 and i w/2 (>= 2) of the layout used where one real
        shift does not cover the strip (3: 0, i w/4, i w/2; the shift 0 is
        the one already made).
    arnoldi_eigenvalues : int
        Eigenvalues computed nearest each shift (>= 1).
    arnoldi_sparse_density : float
        A Jacobian (dense, sparse or by harmonic blocks) with at most this
        fraction of nonzero entries is factorised as a sparse matrix
        (SuperLU) at each shift, a denser one by LAPACK; in (0, 1].
    arnoldi_tol : float
        Relative accuracy of ARPACK's Ritz values (of (A - sigma)^-1; 0:
        machine precision), > 0.
    arnoldi_maxiter : int
        Bound on ARPACK's restarts per shift.
    arnoldi_pole_rtol : float
        Arnoldi through a condensed problem's receptance
        (:mod:`jointdyn.hb.hill_condensed`): a shift where a receptance
        factor's denominator is at most this fraction of its terms' size (a
        structural mode at sigma + i k w) is moved as a singular one (the
        solve there loses about 1e-16 / this of relative accuracy); in (0, 1).
    rtol : float
        A solution is unstable when a selected Floquet exponent has
        Re(s) > ``rtol`` w (a growth Re(s) / w above it); > 0.
    confirm : float
        A growth between ``rtol`` and this is decided by the Floquet
        multipliers of the time-domain period map (Hill's method truncated
        to H harmonics errs by a few 1e-6 at corners of the contact force:
        the onset of slip of an undamped oscillator); >= 0 (at most
        ``rtol``: never).
    small_eig : int
        Hill companion matrices (2 n (2H+1) rows), or their parity blocks,
        of at most this many rows of the points of a branch are assembled
        as one stack and solved by one LAPACK call per parity block (the
        loop over the points in C), larger ones one point at a time (the
        stack's memory grows as points x rows^2); >= 0.
    check_every : int
        The points of a branch whose exponents are computed
        (:mod:`jointdyn.hb.stability_schedule`): 1 (default) every point;
        k > 1 every k-th point of each stretch of joined points, its ends,
        both sides of every turning point, and, where two checked
        neighbours disagree in label, the points between them by bisection
        until the change lies between adjacent points; the other points
        carry the label of their checked neighbours (``stability_checked``
        False, growth NaN). It assumes no exponent crosses the imaginary
        axis and back between two checked points: an unstable stretch
        shorter than k points between two stable checked points is missed.
        A single solution (:func:`~jointdyn.hb.frc.harmonic_balance`) is
        always checked; >= 1.
    """

    method: str = "auto"
    dense_max_rows: int = 500
    arnoldi_shifts: int = 3
    arnoldi_cover_shifts: int = 3
    arnoldi_eigenvalues: int = 12
    arnoldi_sparse_density: float = 0.1
    arnoldi_tol: float = 1e-13
    arnoldi_maxiter: int = 2000
    arnoldi_pole_rtol: float = 1e-8
    rtol: float = 1e-6
    confirm: float = 1e-4
    small_eig: int = 200
    check_every: int = 1

    def __post_init__(self) -> None:
        V.choice("method", self.method, STABILITY_METHODS)
        V.positive_int("dense_max_rows", self.dense_max_rows, 0)
        V.positive_int("arnoldi_shifts", self.arnoldi_shifts, 1)
        V.positive_int("arnoldi_cover_shifts", self.arnoldi_cover_shifts, 2)
        V.positive_int("arnoldi_eigenvalues", self.arnoldi_eigenvalues)
        V.in_range("arnoldi_sparse_density", self.arnoldi_sparse_density, 0.0, 1.0, lo_open=True)
        V.positive("arnoldi_tol", self.arnoldi_tol)
        V.positive_int("arnoldi_maxiter", self.arnoldi_maxiter)
        V.in_range("arnoldi_pole_rtol", self.arnoldi_pole_rtol, 0.0, 1.0, lo_open=True, hi_open=True)
        V.positive("rtol", self.rtol)
        V.nonnegative("confirm", self.confirm)
        V.positive_int("small_eig", self.small_eig, 0)
        V.positive_int("check_every", self.check_every)

    def method_for(self, rows: int) -> str:
        """The method used for a companion matrix of ``rows`` rows: ``dense``, ``arnoldi`` or ``none``."""
        if self.method != "auto":
            return self.method
        return "dense" if rows <= self.dense_max_rows else "arnoldi"


def stability_options(value) -> StabilityOptions:
    """``value`` as StabilityOptions: None (defaults), False (``method="none"``), or StabilityOptions."""
    if value is None:
        return StabilityOptions()
    if value is False:
        return StabilityOptions(method="none")
    if not isinstance(value, StabilityOptions):
        raise ValueError(f"stability must be a StabilityOptions, None (defaults) or False (none), got {value!r}")
    return value
