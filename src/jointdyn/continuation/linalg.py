"""Linear algebra of the continuation: the bordered systems of the Newton step and of the tangent.

LAPACK ``dgesv`` (through NumPy) for most sizes; up to ``LinearSolveOptions.small_solve``
unknowns a compiled Gaussian elimination with partial pivoting
(:func:`lu_solve`, also used by :mod:`jointdyn.modes.qsma`), faster there
because NumPy's per-call overhead costs more than the arithmetic
(``benchmarks/bench_linalg.py``).

From ``config.CONT_KRYLOV_SOLVE`` unknowns (harmonic balance of a structure
with hundreds of node pairs: thousands of unknowns), a factorisation costs
seconds while consecutive points of a branch have nearly the same Jacobian.
There, within one walk (:func:`reusing_factors`), the LU factors of the last
factorised bordered matrix precondition GMRES on the current one
(:class:`FactorReuse`): a few products with the current matrix instead of a
new factorisation. The solution is accepted only when its true residual
``|A x - b| <= krylov_rtol |b|``; otherwise, or after
``krylov_maxiter`` iterations, the current matrix is factorised
and solved directly (and its factors kept for the next solves); after a
solve that needed more than ``krylov_refresh`` iterations, the
next matrix is factorised at once. A sparse matrix (structures with sparse
K, M and C: each pair couples only its own DOFs; R_y may come as a
``scipy.sparse`` matrix) is factorised by SuperLU instead, its factors
reused in the same way, while they stay sparse. The preconditioner changes
the work, not the answer beyond that tolerance: the Newton corrector still
stops on its own residual.

Where the caller knows the structure of its Jacobian (harmonic balance: the
linear terms couple one harmonic only; :func:`preconditioned_by`), the
kept factors are those of that structured preconditioner instead (GMRES
up to ``block_maxiter`` iterations, made anew after a solve
that needed more than ``block_refresh``), made at the current
matrix whenever the kept ones fail, and the whole bordered matrix is
factorised only when even fresh ones fail. The
preconditioner's exact columns (``columns``: dense columns of the unknowns it
does not describe, e.g. EPMC's frequency and damping) and the border row and
column of the continuation enter it exactly by a low-rank (Woodbury)
correction (:class:`_Corrected`). The numbers named are the fields of the walk's
:class:`~jointdyn.continuation.options.LinearSolveOptions` (``ContinuationOptions.linear``).
"""

from __future__ import annotations

import contextlib
import contextvars
import warnings

import numpy as np

from .. import config
from .._jit import jit
from .options import LinearSolveOptions

__all__ = ["FactorReuse", "lu_solve", "preconditioned_by", "reusing_factors"]


@jit
def _merit(R, d, v, u_pred):  # pragma: no cover - compiled
    """max |R| (and |d^T (v - u_pred)| when d has entries); NaN if any entry is NaN."""
    m = 0.0
    for i in range(R.shape[0]):
        a = abs(R[i])
        if a != a:
            return np.nan
        if a > m:
            m = a
    if d.shape[0]:
        c = 0.0
        for i in range(d.shape[0]):
            c += d[i] * (v[i] - u_pred[i])
        c = abs(c)
        if c != c:
            return np.nan
        if c > m:
            m = c
    return m


@jit
def _bordered(Jy, Jl, d):  # pragma: no cover - compiled
    """The matrix [[R_y, R_lam], [d^T]] (or R_y alone when d is empty)."""
    n = Jy.shape[0]
    if d.shape[0] == 0:
        return Jy.copy()
    A = np.empty((n + 1, n + 1))
    for i in range(n):
        for j in range(n):
            A[i, j] = Jy[i, j]
        A[i, n] = Jl[i]
    for j in range(n + 1):
        A[n, j] = d[j]
    return A


@jit
def lu_solve(A, b):  # pragma: no cover - compiled
    """Solve A x = b in place by Gaussian elimination with partial pivoting.

    The algorithm of LAPACK ``dgesv`` (row interchanges by the largest
    pivot, LU factors overwrite A, b becomes x), written out: for small
    systems NumPy's per-call overhead costs more than the arithmetic.
    Returns False for an exactly singular matrix (a zero pivot, where
    ``dgesv`` reports info > 0) or a non-finite solution.
    """
    n = A.shape[0]
    for k in range(n):
        p = k
        amax = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > amax:
                amax = abs(A[i, k])
                p = i
        if amax == 0.0 or amax != amax:
            return False
        if p != k:
            for j in range(n):
                t = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = t
            t = b[k]
            b[k] = b[p]
            b[p] = t
        piv = A[k, k]
        for i in range(k + 1, n):
            f = A[i, k] / piv
            if f != 0.0:
                A[i, k] = f
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
                b[i] -= f * b[k]
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= A[i, j] * b[j]
        b[i] = acc / A[i, i]
        if not np.isfinite(b[i]):
            return False
    return True


@jit
def _border_rhs(R, d, v, u_pred):  # pragma: no cover - compiled
    """Right-hand side (-R, -d^T (v - u_pred)) of a Newton step (-R alone when d is empty)."""
    n = R.shape[0]
    m = n + (1 if d.shape[0] else 0)
    rhs = np.empty(m)
    for i in range(n):
        rhs[i] = -R[i]
    if m > n:
        c = 0.0
        for i in range(m):
            c += d[i] * (v[i] - u_pred[i])
        rhs[n] = -c
    return rhs


@jit
def _normalise(t):  # pragma: no cover - compiled
    """(t / |t|, ok); ok is False for a zero or non-finite norm."""
    nt = 0.0
    for i in range(t.shape[0]):
        nt += t[i] * t[i]
    nt = np.sqrt(nt)
    if not np.isfinite(nt) or nt == 0:
        return t, False
    return t / nt, True


@jit
def _newton_direction_small(Jy, Jl, d, R, v, u_pred):  # pragma: no cover - compiled
    """Newton step by the compiled elimination: ``(dv, ok)``."""
    rhs = _border_rhs(R, d, v, u_pred)
    ok = lu_solve(_bordered(Jy, Jl, d), rhs)
    return rhs, ok


@jit
def _tangent_small(Jy, Jl, t_prev):  # pragma: no cover - compiled
    """Unit tangent by the compiled elimination: ``(t, ok)``."""
    n = Jy.shape[0]
    t = np.zeros(n + 1)
    t[n] = 1.0
    if not lu_solve(_bordered(Jy, Jl, t_prev), t):
        return t, False
    return _normalise(t)


def _lapack_solve(A, b):
    """Solve A x = b by LAPACK ``dgesv``: ``(x, ok)``, ok False for a singular matrix or a non-finite x."""
    try:
        x = np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        return b, False
    return x, bool(np.isfinite(x).all())


def _small(Jy) -> bool:
    """True when the bordered system of R_y is solved by the compiled elimination (see the module docstring)."""
    fr = _REUSE.get()
    return Jy.shape[0] + 1 <= (_DEFAULT_LINEAR if fr is None else fr.linear).small_solve


class FactorReuse:
    """Solves of large bordered systems ``[[R_y, R_lam], [d^T]] x = b`` within one walk (module docstring).

    Keeps the LU factors (``scipy.linalg.lu_factor``) of the last matrix it
    factorised; the next solves run GMRES on the current matrix with those
    factors as (left) preconditioner. A sparse matrix (at most
    ``config.CONT_SPARSE_DENSITY`` of its entries nonzero: a structure with
    sparse K, M, C, whose pairs couple only their own DOFs) is factorised by
    SuperLU (``scipy.sparse.linalg.splu``, the pivot thresholds of
    ``linear.sparse_pivots`` in turn until the solve is accurate)
    instead, and its factors precondition GMRES in the same way, while they
    stay sparse (at most ``linear.sparse_fill`` of N^2 entries; else
    the walk goes on dense). ``counts`` holds the factorisations (dense
    and sparse), the solves accepted from GMRES and its iterations.
    """

    def __init__(self, structure=None, linear: LinearSolveOptions | None = None):
        #: maker of a structured preconditioner (:func:`preconditioned_by`), or None
        self.structure = structure
        #: the numbers of the solves (default ``LinearSolveOptions()``)
        self.linear = _DEFAULT_LINEAR if linear is None else linear
        self.blocks = None  # its kept factors
        self.lu = None
        self.splu = None  # the kept sparse factors (scipy.sparse.linalg.SuperLU)
        self.stale = False
        self.sparse = None  # decided at the first factorisation of the walk
        self.counts = {"factorisations": 0, "krylov_solves": 0, "krylov_iterations": 0, "sparse_factorisations": 0}
        if structure is not None:
            self.counts.update(block_factorisations=0, block_fallbacks=0)

    def solve(self, Jy, Jl, d, b):
        """``(x, ok)``: the solution of the bordered system (R_y alone when ``d`` is empty)."""
        import scipy.linalg as sla  # here: small problems never need it, and the CLI starts without it

        n = Jy.shape[0]
        if getattr(Jy, "approximation", None) is not None:  # a sparse matrix plus an operator
            x = self._approximated(Jy, Jl, d, b)
            if x is not None:
                return x, True
            self.counts["approximation_fallbacks"] = self.counts.get("approximation_fallbacks", 0) + 1
            return _lapack_solve(_bordered(Jy.toarray(), Jl, d), b)
        if self.sparse is None:
            if _is_structured(Jy):  # its caller chose the blocks for a dense structure
                self.sparse = False
            else:
                nnz = Jy.nnz if _is_sparse(Jy) else np.count_nonzero(Jy)
                self.sparse = nnz <= config.CONT_SPARSE_DENSITY * n * n
        if self.sparse:
            return self._sparse(Jy, Jl, d, b)
        if self.structure is not None:  # where SuperLU does not apply: a matrix dense in its blocks
            x = self._structured(Jy, Jl, d, b)
            if x is not None:
                return x, True
            self.counts["block_fallbacks"] += 1
        Jy = _dense(Jy)  # a sparse R_y whose factors filled in: dense from then on
        if self.lu is not None and self.lu[0].shape[0] == b.size and not self.stale:
            lu = self.lu
            x = self._krylov(lambda x: _bordered_times(Jy, Jl, d, x), lambda r: sla.lu_solve(lu, r, check_finite=False),
                             b)
            if x is not None:
                return x, True
        self.stale = False
        A = _bordered(Jy, Jl, d)
        with warnings.catch_warnings():  # an exactly singular matrix is reported by ok = False below
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu = sla.lu_factor(A, overwrite_a=True, check_finite=False)
        self.counts["factorisations"] += 1
        if not np.all(np.isfinite(lu[0].diagonal())) or np.any(lu[0].diagonal() == 0.0):
            self.lu = None
            return b, False
        self.lu = lu
        x = sla.lu_solve(lu, b, check_finite=False)
        return x, bool(np.isfinite(x).all())

    def _sparse(self, Jy, Jl, d, b):
        """``(x, ok)`` by the kept sparse factors (GMRES, as the dense ones) or SuperLU on this matrix
        (``self.sparse`` False when its factors filled in: dense from then on)."""
        import scipy.sparse.linalg as spla

        A = _sparse_bordered(Jy, Jl, d)
        f = self.splu
        if f is not None and f.shape == A.shape and not self.stale:
            x = self._krylov(A.dot, f.solve, b)
            if x is not None:
                return x, True
        self.stale = False
        f = x = None
        nb = np.linalg.norm(b)
        for thresh in self.linear.sparse_pivots:  # the diagonal pivots first (least fill), then safer ones
            try:
                f = spla.splu(A, diag_pivot_thresh=thresh)
            except RuntimeError:  # exactly singular with these pivots
                f = None
                continue
            self.counts["sparse_factorisations"] += 1
            x = f.solve(b)
            if np.isfinite(x).all() and np.linalg.norm(A @ x - b) <= self.linear.krylov_rtol * nb:
                break
        self.splu = f
        if f is None:
            return b, False
        if f.L.nnz + f.U.nnz > self.linear.sparse_fill * A.shape[0] ** 2:
            self.sparse, self.splu = False, None
        return x, bool(np.isfinite(x).all())

    def _approximated(self, Jy, Jl, d, b):
        """x by GMRES on the exact product of ``Jy`` preconditioned by the SuperLU factors of its sparse
        ``approximation()`` (the kept ones, else fresh ones of this matrix), or None when even fresh ones do not
        reach the tolerance (the caller solves directly). Harmonic balance with modal damping as an operator:
        :mod:`jointdyn.hb._damped`."""
        import scipy.sparse.linalg as spla

        def times(x):
            return _bordered_times(Jy, Jl, d, x)

        A = _sparse_bordered(Jy.approximation(), Jl, d)
        f = self.splu
        if f is not None and f.shape == A.shape and not self.stale:
            x = self._krylov(times, f.solve, b, self.linear.block_maxiter, right=True)
            if x is not None:
                return x
        self.stale, self.splu = False, None
        for thresh in self.linear.sparse_pivots:  # the diagonal pivots first (least fill), then safer ones
            try:
                f = spla.splu(A, diag_pivot_thresh=thresh)
            except RuntimeError:  # exactly singular with these pivots
                continue
            self.counts["sparse_factorisations"] += 1
            x = self._krylov(times, f.solve, b, self.linear.block_maxiter, right=True)
            if x is not None:
                self.splu = f
                return x
        return None

    def _structured(self, Jy, Jl, d, b):
        """x by GMRES preconditioned with the structured factors (the kept ones, else fresh ones of this
        matrix), or None when even fresh ones do not reach the tolerance (the caller solves directly)."""
        def times(x):
            return _bordered_times(Jy, Jl, d, x)

        f = self.blocks
        k = self.linear.block_maxiter
        if f is not None and f.size == Jy.shape[0] and not self.stale:
            P = _Corrected.of(f, Jy, Jl, d)
            before = self.counts["krylov_iterations"]
            x = None if P is None else self._krylov(times, P.solve, b, k, right=True)
            # fresh blocks need some iterations too (the harmonics' coupling): the kept ones are dropped only
            # when they need many more (a fresh factorisation costs about as much as CONT_BLOCK_REFRESH iterations)
            self.stale = self.counts["krylov_iterations"] - before > self.linear.block_refresh
            if x is not None:
                return x
        self.blocks = f = self.structure.factor(Jy)
        self.counts["block_factorisations"] += 1
        P = None if f is None else _Corrected.of(f, Jy, Jl, d)
        x = None if P is None else self._krylov(times, P.solve, b, k, right=True)
        self.stale = False
        return x

    def _krylov(self, times, precondition, b, k=None, right=False):
        """GMRES on ``times`` (the current matrix's product) preconditioned by ``precondition`` (a solve with
        the kept factors), at most ``k`` iterations (default ``linear.krylov_maxiter``); the solution,
        or None when not accurate enough. ``right``: preconditioned from the right, so that GMRES stops on
        the true residual (an approximate preconditioner of a nearly singular matrix, as the harmonic
        blocks at a resonance, has a large inverse: the left-preconditioned residual would stop it while
        the true one is still far from the tolerance)."""
        import scipy.sparse.linalg as spla

        it = [0]

        def count(_):
            it[0] += 1

        k = self.linear.krylov_maxiter if k is None else k
        tol = dict(rtol=0.1 * self.linear.krylov_rtol, atol=0.0, restart=k, maxiter=1, callback=count,
                   callback_type="pr_norm")
        if right:
            AP = spla.LinearOperator((b.size, b.size), matvec=lambda y: times(precondition(y)), dtype=np.float64)
            y, _ = spla.gmres(AP, b, x0=b.copy(), **tol)
            x = precondition(y)
        else:
            A = spla.LinearOperator((b.size, b.size), matvec=times, dtype=np.float64)
            P = spla.LinearOperator((b.size, b.size), matvec=precondition, dtype=np.float64)
            x, _ = spla.gmres(A, b, x0=P.matvec(b), M=P, **tol)
        self.counts["krylov_iterations"] += it[0]
        nb = np.linalg.norm(b)
        if not np.isfinite(x).all() or np.linalg.norm(times(x) - b) > self.linear.krylov_rtol * nb:
            return None
        self.counts["krylov_solves"] += 1
        # the factors drift from the walk's matrices: factorise at the next solve instead of first
        # spending GMRES iterations on a preconditioner that is likely to fail
        self.stale = it[0] > self.linear.krylov_refresh
        return x


class _Corrected:
    """Solves with the bordered matrix of :func:`_bordered` in which R_y is replaced by a structured
    approximation ``f`` (its factors: ``f.solve``, ``f.column``), except on the columns ``f.columns``,
    which are R_y's own, and on the border (exact): ``P = D + W Z^T`` with D = diag(f, 1) and a correction
    of rank ``len(f.columns)`` (+ 2 with a border), solved by the Woodbury identity (r + 1 solves with f
    to set it up, one per application)."""

    def __init__(self, f, W, Z):
        self.f, self.Z = f, Z
        self.n = f.size
        self.Y = self._base(W)
        cap = np.eye(Z.shape[1]) + Z.T @ self.Y
        self.cap = np.linalg.inv(cap)  # r x r, r <= 4

    @classmethod
    def of(cls, f, Jy, Jl, d):
        """The corrected preconditioner, or None where its small capacitance matrix is singular."""
        n = Jy.shape[0]
        m = n + (1 if d.shape[0] else 0)
        cols = [int(j) for j in f.columns]
        Ws, Zs = [], []
        for j in cols:
            c = np.zeros(m)
            c[:n] = _column(Jy, j) - f.column(j)
            if m > n:
                c[n] = d[j]
            Ws.append(c)
            Zs.append(_unit(m, j))
        if m > n:
            Ws.append(np.append(Jl, d[n] - 1.0))
            Zs.append(_unit(m, n))
            row = np.array(d, dtype=np.float64)
            row[cols] = 0.0
            row[n] = 0.0
            Ws.append(_unit(m, n))
            Zs.append(row)
        if not Ws:
            return cls(f, np.zeros((m, 0)), np.zeros((m, 0)))
        try:
            return cls(f, np.stack(Ws, axis=1), np.stack(Zs, axis=1))
        except np.linalg.LinAlgError:
            return None

    def _base(self, r):
        """D^-1 r (one vector or columns)."""
        out = np.array(r, dtype=np.float64)
        out[:self.n] = self.f.solve(out[:self.n])
        return out

    def solve(self, r):
        y = self._base(r)
        if self.Z.shape[1]:
            y -= self.Y @ (self.cap @ (self.Z.T @ y))
        return y


def _unit(m, j):
    e = np.zeros(m)
    e[j] = 1.0
    return e


def _column(Jy, j):
    """Column j of R_y (dense, sparse or structured) as a 1-D array."""
    if _is_structured(Jy):
        return Jy.column(j)
    if _is_sparse(Jy):
        return np.asarray(Jy[:, [j]].toarray()).ravel()
    return np.array(Jy[:, j])


def _bordered_times(Jy, Jl, d, x):
    """The bordered matrix of :func:`_bordered` times x, without forming it."""
    n = Jy.shape[0]
    y = Jy @ x[:n]
    if d.shape[0] > 0:
        y = np.append(y + Jl * x[n], d @ x)
    return y


def _sparse_bordered(Jy, Jl, d):
    """The bordered matrix of :func:`_bordered` as a CSC matrix, from the nonzeros of R_y (no dense copy;
    R_y itself when sparse)."""
    import scipy.sparse as sps

    n = Jy.shape[0]
    if _is_sparse(Jy):
        if d.shape[0] == 0:
            return sps.csc_matrix(Jy)
        return sps.bmat([[Jy, Jl[:, None]], [d[None, :n], d[n:, None]]], format="csc")
    idx = np.flatnonzero(Jy)
    r, c = np.divmod(idx, n)
    if d.shape[0] == 0:
        return sps.csc_matrix((Jy.ravel()[idx], (r, c)), shape=(n, n))
    rows = np.concatenate((r, np.arange(n), np.full(n + 1, n)))
    cols = np.concatenate((c, np.full(n, n), np.arange(n + 1)))
    return sps.csc_matrix((np.concatenate((Jy.ravel()[idx], Jl, d)), (rows, cols)), shape=(n + 1, n + 1))


#: the numbers of solves outside any walk
_DEFAULT_LINEAR = LinearSolveOptions()
_REUSE: contextvars.ContextVar[FactorReuse | None] = contextvars.ContextVar("jointdyn_factor_reuse", default=None)
_STRUCTURE = contextvars.ContextVar("jointdyn_structured_preconditioner", default=None)


@contextlib.contextmanager
def preconditioned_by(structure):
    """Within the block, the large solves of new walks (:func:`reusing_factors`) are preconditioned by
    ``structure`` (None: the direct path).

    ``structure.factor(R_y)`` returns factors of an approximation of R_y
    (or None where one is singular) with ``size`` (rows of R_y),
    ``solve(r)`` (one vector or columns), ``column(j)`` (column j of the
    approximation) and ``columns`` (the columns of R_y that it does not
    describe: they are taken from R_y exactly, :class:`_Corrected`).
    """
    token = _STRUCTURE.set(structure)
    try:
        yield
    finally:
        _STRUCTURE.reset(token)


@contextlib.contextmanager
def reusing_factors(linear: LinearSolveOptions | None = None):
    """Within the block, large bordered solves reuse factors (:class:`FactorReuse`, solving by the numbers
    of ``linear``, default ``LinearSolveOptions()``); yields it.

    Nested blocks share the outer one (and its numbers). The factors are dropped on exit.
    """
    outer = _REUSE.get()
    if outer is not None:
        yield outer
        return
    fr = FactorReuse(_STRUCTURE.get(), linear)
    token = _REUSE.set(fr)
    try:
        yield fr
    finally:
        _REUSE.reset(token)


def _large_solve(Jy, Jl, d, b):
    """A bordered solve above ``small_solve`` unknowns: with reused factors where they pay, else ``dgesv``."""
    fr = _REUSE.get()
    if fr is not None and Jy.shape[0] + 1 >= config.CONT_KRYLOV_SOLVE:
        return fr.solve(Jy, Jl, d, b)
    return _lapack_solve(_bordered(_dense(Jy), Jl, d), b)


def _is_sparse(Jy) -> bool:
    """True for a ``scipy.sparse`` Jacobian (a residual may return one at thousands of unknowns: interfaces on
    a sparse structure, :meth:`jointdyn.hb.HBProblem.evaluate_sparse`); without importing scipy."""
    return type(Jy) is not np.ndarray and hasattr(Jy, "tocsc")


def _is_structured(Jy) -> bool:
    """True for a Jacobian that is neither an array nor a sparse matrix but its caller's structure (a
    product ``@``, ``toarray()``, ``column(j)``; harmonic balance's blocks, ``jointdyn.hb._jacobian``)."""
    return getattr(Jy, "structured", False) is True


def _dense(Jy):
    """R_y as a dense array (a sparse or structured one converted)."""
    return Jy.toarray() if _is_sparse(Jy) or _is_structured(Jy) else Jy


def _newton_direction(Jy, Jl, d, R, v, u_pred):
    """Newton step of R(y, lam) = 0 (and d^T (v - u_pred) = 0 when d has entries): ``(dv, ok)``."""
    if _small(Jy):
        Jy = _dense(Jy)
        return _newton_direction_small(Jy, Jl, d, R, v, u_pred)
    return _large_solve(Jy, Jl, d, _border_rhs(R, d, v, u_pred))


def _tangent(Jy, Jl, t_prev):
    """Unit t with [R_y R_lam] t = 0, t_prev^T t = 1 (normalised), or None if singular."""
    f = np.float64
    Jl = np.ascontiguousarray(Jl, dtype=f).reshape(-1)
    if (_is_sparse(Jy) or _is_structured(Jy)) and _small(Jy):
        Jy = _dense(Jy)
    if not (_is_sparse(Jy) or _is_structured(Jy)):
        Jy = np.ascontiguousarray(Jy, dtype=f).reshape(Jl.size, -1)
    t_prev = np.ascontiguousarray(t_prev, dtype=f)
    if _small(Jy):
        t, ok = _tangent_small(Jy, Jl, t_prev)
    else:
        e = np.zeros(Jy.shape[0] + 1)
        e[-1] = 1.0
        t, ok = _large_solve(Jy, Jl, t_prev, e)
        if ok:
            t, ok = _normalise(t)
    return t if ok else None


def _as_arrays(R, Jy, Jl):
    """(R, R_y, R_lam) as C-contiguous float64 arrays of dims 1, 2, 1 (no copy when they are); a
    ``scipy.sparse`` R_y is passed on as it is (:func:`_is_sparse`)."""
    f = np.float64
    if _is_sparse(Jy) or _is_structured(Jy):
        R = np.ascontiguousarray(R, dtype=f).reshape(-1)
        return R, Jy, np.ascontiguousarray(Jl, dtype=f).reshape(-1)
    if (type(R) is np.ndarray and type(Jy) is np.ndarray and type(Jl) is np.ndarray and R.dtype == f
            and Jy.dtype == f and Jl.dtype == f and R.ndim == 1 and Jy.ndim == 2 and Jl.ndim == 1
            and R.flags.c_contiguous and Jy.flags.c_contiguous and Jl.flags.c_contiguous):
        return R, Jy, Jl
    R = np.ascontiguousarray(R, dtype=f).reshape(-1)
    return R, np.ascontiguousarray(Jy, dtype=f).reshape(R.size, -1), np.ascontiguousarray(Jl, dtype=f).reshape(-1)
