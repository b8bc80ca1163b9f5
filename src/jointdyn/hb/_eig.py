"""Eigenvalues of a small real matrix, compiled (Hill's method, stability.py).

Hill's method needs all eigenvalues of a 2 n (2H+1) square real matrix at
every branch point (30 x 30 for one DOF and H = 7). LAPACK's ``dgeev``
through NumPy costs ~0.1 ms there, mostly fixed overheads of its blocked
code paths at this size; the classical EISPACK sequence below, compiled,
takes about half:

* ``_balance``: diagonal similarity by powers of 2 (exact in floating
  point) equilibrating row and column norms (Parlett & Reinsch, Numer.
  Math. 13, 1969; EISPACK ``balanc``);
* ``_elmhes``: reduction to upper Hessenberg form by stabilised elementary
  similarity transformations (Gaussian elimination with partial pivoting;
  Martin & Wilkinson, Numer. Math. 12, 1968; EISPACK ``elmhes``);
* ``_hqr``: eigenvalues of the Hessenberg matrix by the Francis
  double-shift QR iteration with Wilkinson's exceptional shifts (Martin,
  Peters & Wilkinson, Numer. Math. 14, 1970; EISPACK ``hqr``; the
  0-indexed form follows Press et al., Numerical Recipes, 2nd ed., 11.6).

These are the algorithms of the Handbook for Automatic Computation
(Wilkinson & Reinsch, 1971) on which LAPACK's ``dgeev`` builds; the
results agree with it to rounding (tests/test_hb_eig.py). When the QR
iteration does not converge within 60 iterations for one eigenvalue,
:func:`eigvals_real` reports it and the caller falls back to LAPACK.
"""

from __future__ import annotations

import numpy as np

from .._jit import jit

__all__ = ["eigvals_real"]

@jit
def _balance(a):
    """Balance ``a`` in place by a diagonal similarity with powers of 2."""
    n = a.shape[0]
    radix = 2.0
    sqrdx = radix * radix
    done = False
    while not done:
        done = True
        for i in range(n):
            r = 0.0
            c = 0.0
            for j in range(n):
                if j != i:
                    c += abs(a[j, i])
                    r += abs(a[i, j])
            if c != 0.0 and r != 0.0:
                g = r / radix
                f = 1.0
                s = c + r
                while c < g:
                    f *= radix
                    c *= sqrdx
                g = r * radix
                while c > g:
                    f /= radix
                    c /= sqrdx
                if (c + r) / f < 0.95 * s:
                    done = False
                    g = 1.0 / f
                    for j in range(n):
                        a[i, j] *= g
                    for j in range(n):
                        a[j, i] *= f

@jit
def _elmhes(a):
    """Reduce ``a`` in place to upper Hessenberg form (multipliers left below the subdiagonal)."""
    n = a.shape[0]
    for m in range(1, n - 1):
        x = 0.0
        i = m
        for j in range(m, n):
            if abs(a[j, m - 1]) > abs(x):
                x = a[j, m - 1]
                i = j
        if i != m:
            for j in range(m - 1, n):
                t = a[i, j]
                a[i, j] = a[m, j]
                a[m, j] = t
            for j in range(n):
                t = a[j, i]
                a[j, i] = a[j, m]
                a[j, m] = t
        if x != 0.0:
            for i in range(m + 1, n):
                y = a[i, m - 1]
                if y != 0.0:
                    y /= x
                    a[i, m - 1] = y
                    for j in range(m, n):
                        a[i, j] -= y * a[m, j]
                    for j in range(n):
                        a[j, m] += y * a[j, i]

@jit
def _hqr(a, wr, wi):
    """Eigenvalues ``wr + i wi`` of the upper Hessenberg matrix ``a`` (destroyed).

    Entries below the subdiagonal are ignored (they may hold the
    multipliers of :func:`_elmhes`). Returns False if an eigenvalue needed
    more than 60 iterations.
    """
    n = a.shape[0]
    anorm = 0.0
    for i in range(n):
        for j in range(max(i - 1, 0), n):
            anorm += abs(a[i, j])
    nn = n - 1
    t = 0.0
    while nn >= 0:
        its = 0
        while True:
            l = _split_point(a, nn, anorm)
            left = _deflate(a, wr, wi, l, nn, t)
            if left != nn:
                nn = left
                break
            if its == 60:
                return False
            x = a[nn, nn]
            y = a[nn - 1, nn - 1]
            w = a[nn, nn - 1] * a[nn - 1, nn]
            if its == 10 or its == 20 or its == 40:
                # exceptional shift
                t += x
                for i in range(nn + 1):
                    a[i, i] -= x
                s = abs(a[nn, nn - 1]) + abs(a[nn - 1, nn - 2])
                x = 0.75 * s
                y = x
                w = -0.4375 * s * s
            its += 1
            m, p, q, r = _shift_start(a, l, nn, x, y, w)
            _double_shift_sweep(a, l, m, nn, p, q, r)
    return True


@jit
def _split_point(a, nn, anorm):  # pragma: no cover - compiled
    """Start l of the unreduced block ending at row nn (a negligible subdiagonal entry is set to 0)."""
    for ll in range(nn, 0, -1):
        s = abs(a[ll - 1, ll - 1]) + abs(a[ll, ll])
        if s == 0.0:
            s = anorm
        if abs(a[ll, ll - 1]) + s == s:
            a[ll, ll - 1] = 0.0
            return ll
    return 0


@jit
def _deflate(a, wr, wi, l, nn, t):  # pragma: no cover - compiled
    """Roots of a 1 x 1 (l == nn) or 2 x 2 (l == nn - 1) trailing block; the new last row.

    Returns nn unchanged when the block is larger (no root found).
    """
    x = a[nn, nn]
    if l == nn:
        wr[nn] = x + t
        wi[nn] = 0.0
        return nn - 1
    if l != nn - 1:
        return nn
    y = a[nn - 1, nn - 1]
    w = a[nn, nn - 1] * a[nn - 1, nn]
    p = 0.5 * (y - x)
    q = p * p + w
    z = np.sqrt(abs(q))
    x += t
    if q >= 0.0:
        z = p + (z if p >= 0.0 else -z)
        wr[nn - 1] = x + z
        wr[nn] = x + z
        if z != 0.0:
            wr[nn] = x - w / z
        wi[nn - 1] = 0.0
        wi[nn] = 0.0
    else:
        wr[nn - 1] = x + p
        wr[nn] = x + p
        # conjugate pair, positive imaginary part first (as LAPACK)
        wi[nn - 1] = z
        wi[nn] = -z
    return nn - 2


@jit
def _shift_start(a, l, nn, x, y, w):  # pragma: no cover - compiled
    """Row m where the double-shift sweep starts (two small consecutive subdiagonal entries),
    and the first column (p, q, r) of the shifted matrix there."""
    p = q = r = 0.0
    m = nn - 2
    while m >= l:
        z = a[m, m]
        r = x - z
        s = y - z
        p = (r * s - w) / a[m + 1, m] + a[m, m + 1]
        q = a[m + 1, m + 1] - z - r - s
        r = a[m + 2, m + 1]
        s = abs(p) + abs(q) + abs(r)
        p /= s
        q /= s
        r /= s
        if m == l:
            break
        u = abs(a[m, m - 1]) * (abs(q) + abs(r))
        v = abs(p) * (abs(a[m - 1, m - 1]) + abs(z) + abs(a[m + 1, m + 1]))
        if u + v == v:
            break
        m -= 1
    return m, p, q, r


@jit
def _double_shift_sweep(a, l, m, nn, p, q, r):  # pragma: no cover - compiled
    """One Francis double-shift QR step on rows and columns l..nn, from row m."""
    x = y = z = 0.0
    for i in range(m + 2, nn + 1):
        a[i, i - 2] = 0.0
        if i != m + 2:
            a[i, i - 3] = 0.0
    for k in range(m, nn):
        if k != m:
            p = a[k, k - 1]
            q = a[k + 1, k - 1]
            r = 0.0
            if k != nn - 1:
                r = a[k + 2, k - 1]
            x = abs(p) + abs(q) + abs(r)
            if x != 0.0:
                p /= x
                q /= x
                r /= x
        s = np.sqrt(p * p + q * q + r * r)
        if p < 0.0:
            s = -s
        if s != 0.0:
            if k == m:
                if l != m:
                    a[k, k - 1] = -a[k, k - 1]
            else:
                a[k, k - 1] = -s * x
            p += s
            x = p / s
            y = q / s
            z = r / s
            q /= p
            r /= p
            for j in range(k, nn + 1):
                p = a[k, j] + q * a[k + 1, j]
                if k != nn - 1:
                    p += r * a[k + 2, j]
                    a[k + 2, j] -= p * z
                a[k + 1, j] -= p * y
                a[k, j] -= p * x
            mmin = nn if nn < k + 3 else k + 3
            for i in range(l, mmin + 1):
                p = x * a[i, k] + y * a[i, k + 1]
                if k != nn - 1:
                    p += z * a[i, k + 2]
                    a[i, k + 2] -= p * r
                a[i, k + 1] -= p * q
                a[i, k] -= p


@jit
def eigvals_inplace(a):
    """Eigenvalues of the real square matrix ``a`` (overwritten).

    Returns ``(eigenvalues complex (n,), ok)``; ``ok`` is False when the QR
    iteration did not converge (the values are then not to be used).
    """
    n = a.shape[0]
    wr = np.zeros(n)
    wi = np.zeros(n)
    _balance(a)
    _elmhes(a)
    ok = _hqr(a, wr, wi)
    out = np.empty(n, dtype=np.complex128)
    for i in range(n):
        out[i] = complex(wr[i], wi[i])
    return out, ok


@jit
def eigvals_real(A):
    """Eigenvalues of the real square matrix ``A`` (not modified): ``(values, ok)``."""
    return eigvals_inplace(np.ascontiguousarray(A).copy())
