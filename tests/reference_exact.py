"""Plain-Python reference of the exact Iwan law (``iwan``, the default).

Written from the algorithm of ``jointdyn.laws.exact`` (module docstring) and
MODEL.md sections 2, 3 and 5, without its state vector, its kernels or
numpy: the state is a Python list of pieces ``[lo, hi, a, b]`` (P(u) = a +
b u on [lo, hi], u the slip strength in units of fy, P in units of fy), and
each step is done the straightforward way:

1. separation (N <= 0) or no friction: P = 0 (one piece), T = 0;
2. every element gets dq = (kt / fy)(x - x_prev);
3. each piece is cut where it crosses a clip line +-alpha u (a cut closer
   than ``SNAP`` to an end of the piece is dropped) and each segment is
   classified at its midpoint: above the upper line (P = alpha u), below the
   lower line (P = -alpha u) or stuck (unchanged);
4. adjacent pieces with identical coefficients are joined;
5. while there are more than ``capacity`` pieces, three adjacent pieces
   j-1, j, j+1 (vertices (u0, p0) .. (u3, p3)) are replaced by two through
   a new vertex at uw = (u1 + u2) / 2 whose value keeps the integral of P
   over [u0, u3]; only merges whose new vertex lies within the limits
   (|pw| <= alpha uw) are candidates, and the j chosen is the first with the
   least (|change of P at u1| + |change of P at u2|) (u3 - u0) (if there is
   no candidate: j = 1, with pw clamped to the limits); a new piece within
   SNAP * alpha of a clip line over [0, its upper end] is put on it;
6. T = fy / 2 * integral of P over [0, 2], kT = kt / 2 * (measure of the
   pieces that are not on a clip line).

The object commits on every :meth:`ExactIwanRef.step`; ``march_ref`` of
``tests/reference.py`` marches it like the other references.
"""

from __future__ import annotations

STICK_SLIP, MACROSLIP, SEPARATION = 0, 1, 2

#: cuts closer than this to an end of a piece are dropped (units of u), the
#: tolerance documented in laws/exact.py
SNAP = 1e-9
U_MAX = 2.0


def _line(u0, p0, u1, p1, alpha):
    """Piece [u0, u1] through (u0, p0), (u1, p1), put on a clip line when it
    lies within SNAP * alpha of it over [0, u1]."""
    b = (p1 - p0) / (u1 - u0)
    a = p0 - b * u0
    if abs(a) + abs(abs(b) - alpha) * u1 <= SNAP * alpha:
        a, b = 0.0, (alpha if b > 0.0 else -alpha)
    return [u0, u1, a, b]


def _on_line(a, b, alpha):
    return a == 0.0 and (b == alpha or b == -alpha)


class ExactIwanRef:
    """The exact Iwan law, one piece at a time (module docstring).

    Parameters: kt (N/m), mu, n_ref (N), capacity (pieces), and the virgin
    state's displacement x0 (m); the load ``n0`` does not enter the virgin
    state.
    """

    def __init__(self, kt, mu, n_ref, capacity, x0=0.0, n0=None):
        self.kt = float(kt)
        self.fy = float(mu) * float(n_ref)
        self.n_ref = float(n_ref)
        self.capacity = int(capacity)
        self.x_prev = float(x0)
        self.pieces = [[0.0, U_MAX, 0.0, 0.0]]

    # --- one step ---------------------------------------------------------
    def step(self, x, N):
        alpha = N * (1.0 / self.n_ref)  # the kernel's rounding of alpha
        if alpha <= 0.0 or self.fy <= 0.0:
            self.pieces = [[0.0, U_MAX, 0.0, 0.0]]
            self.x_prev = x
            return 0.0, 0.0, (SEPARATION if alpha <= 0.0 else MACROSLIP)
        dq = self.kt / self.fy * (x - self.x_prev)
        self.x_prev = x
        new = []
        for lo, hi, a, b in self.pieces:
            for seg in self._clip(lo, hi, a + dq, b, alpha):
                if new and new[-1][2] == seg[2] and new[-1][3] == seg[3]:
                    new[-1][1] = seg[1]
                else:
                    new.append(seg)
        while len(new) > self.capacity:
            self._merge_least(new, alpha)
        self.pieces = new
        return self._outputs(alpha)

    @staticmethod
    def _clip(lo, hi, a, b, alpha):
        """Segments of a + b u on [lo, hi] after the clip to [-alpha u, alpha u]."""
        cuts = [lo, hi]
        for slope in (b - alpha, b + alpha):  # a + slope u = 0 on a clip line
            if slope != 0.0:
                c = -a / slope
                if lo + SNAP < c < hi - SNAP:
                    cuts.append(c)
        cuts.sort()
        out = []
        for l, h in zip(cuts[:-1], cuts[1:]):
            if h <= l:
                continue
            mid = 0.5 * (l + h)
            v = a + b * mid
            if v > alpha * mid:
                out.append([l, h, 0.0, alpha])
            elif v < -alpha * mid:
                out.append([l, h, 0.0, -alpha])
            else:
                out.append([l, h, a, b])
        return out

    @staticmethod
    def _merge_least(pieces, alpha):
        """Merge the least-cost three adjacent pieces into two (in place)."""

        def value(piece, u):
            return piece[2] + piece[3] * u

        def integral(piece):
            lo, hi, a, b = piece
            return (hi - lo) * (a + 0.5 * b * (hi + lo))

        best = None
        for j in range(1, len(pieces) - 1):
            left, mid, right = pieces[j - 1], pieces[j], pieces[j + 1]
            u0, u1, u2, u3 = left[0], left[1], mid[1], right[1]
            p0, p1, p2, p3 = value(left, u0), value(left, u1), value(mid, u2), value(right, u3)
            area2 = 2.0 * (integral(left) + integral(mid) + integral(right))
            uw = 0.5 * (u1 + u2)
            # trapezoids u0 -> uw -> u3 with the same area; the cost is
            # compared as a fraction num / den, written with the kernel's
            # operations: it decides between near-equal candidates and the
            # line snap is a threshold, so both implementations round alike
            d, wl, wr = u3 - u0, uw - u0, u3 - uw
            pwd = area2 - wl * p0 - wr * p3  # pw * d
            e1 = (p0 - p1) * wl * d + (pwd - p0 * d) * (u1 - u0)  # (change at u1) wl d
            e2 = (pwd - p2 * d) * wr + (p3 * d - pwd) * (u2 - uw)  # (change at u2) wr d
            if abs(pwd) > alpha * uw * d:
                continue  # the vertex would leave the limits: not a candidate
            num, den = abs(e1) * wr + abs(e2) * wl, wl * wr
            if best is None or num * best[1] < best[0] * den:
                best = (num, den, j)
        j = 1 if best is None else best[2]  # no admissible merge: the first, clamped
        left, mid, right = pieces[j - 1], pieces[j], pieces[j + 1]
        u0, u1, u2, u3 = left[0], left[1], mid[1], right[1]
        p0, p3 = value(left, u0), value(right, u3)
        area2 = 2.0 * (integral(left) + integral(mid) + integral(right))
        uw = 0.5 * (u1 + u2)
        pw = (area2 - (uw - u0) * p0 - (u3 - uw) * p3) / (u3 - u0)
        pw = min(max(pw, -alpha * uw), alpha * uw)
        pieces[j - 1 : j + 2] = [_line(u0, p0, uw, pw, alpha), _line(uw, pw, u3, p3, alpha)]

    def _outputs(self, alpha):
        total = 0.0
        stuck = 0.0
        for lo, hi, a, b in self.pieces:
            total += a * (hi - lo) + 0.5 * b * (hi * hi - lo * lo)
            if not _on_line(a, b, alpha):
                stuck += hi - lo
        code = STICK_SLIP if stuck > 0.0 else MACROSLIP
        return 0.5 * self.fy * total, 0.5 * self.kt * stuck, code
