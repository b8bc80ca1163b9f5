"""Closed-form Iwan model with time-varying normal load (docs/model.md sections 2-4).

Uniform slip density on [0, 2 alpha fy], alpha(t) = N(t)/N_ref. The force on
a branch that started at a reversal point (q0, G0, alpha0) is the modified
Masing rule (paper section 2.1, normalised form; docs/model.md section 3)::

    G = G0 + d c G_oa(|q - q0| / c; alpha),   c = 1 + alpha0 / alpha,
    G_oa(u; a) = u - u^2 / (4 a)  (u < 2a),   a  (u >= 2a),

with q = kt x / fy, G = T / fy and d the direction of motion, clipped to
|G| <= alpha (macroslip). Two memory rules are offered:

``memory="full"`` (default)
    Masing's extended rules: a stack of reversal points; a branch that
    reaches an earlier reversal point rejoins the branch that point belonged
    to and both points are forgotten. When the clip is active every slider
    slips, so the memory is wiped and the saturation point (q_s, alpha_s)
    is remembered: continuing in the same direction after alpha rises, the
    sliders re-stick and G = d alpha_s + d G_oa(|q - q_s|; alpha - alpha_s)
    (exact for the uniform density). At constant alpha this equals the
    discrete model (n -> inf) for ANY history. When alpha has changed since
    the forgotten reversal points, the rejoined branch no longer passes
    through the current point; the difference is kept as a constant force
    offset on the rejoined branch (on its G0, or on the base curve), which
    is zero at constant alpha and keeps T continuous.
``memory="last"``
    The paper's rule: only the last reversal point is kept (exact for steady
    symmetric cycles at constant alpha, wrong for nested or growing loops);
    branch formula and clip applied at every step. The paper writes
    -G_oa(q0) where we use the actual force G0 at the reversal; the two
    agree on steady cycles at constant alpha and G0 keeps T continuous.

Separation (alpha <= 0): T = 0, all memory lost; the next contact starts a
virgin curve G = G_oa(q - q_c; alpha) from the re-contact point q_c.

Registered as ``iwan-closed`` (full memory) and ``iwan-paper`` (last
reversal). Neither rule sees the elements that slip because the normal load
falls while a branch is followed (the branch formula scales a curve fixed
at the reversal point): the closed forms are exact at constant load and for
loads in phase with the motion only. The default contact law is the exact
model, :class:`~jointdyn.Iwan` (``iwan``, :mod:`jointdyn.laws.exact`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .._jit import jit
from ._base import MACROSLIP, SEPARATION, STICK_SLIP, ContactLaw, law_param, register

__all__ = ["IwanClosedForm", "closed_step", "closed_step_jvp", "closed_init", "closed_init_jvp", "backbone"]

#: capacity of the reversal-point stack of the closed-form Iwan law
IWAN_CLOSED_MAX_DEPTH = 64
#: a branch of the closed-form Iwan law closer than this to an earlier
#: reversal point (normalised displacement kt x / fy) has reached it (Masing
#: rejoin); the force error is of the same order in units of fy
IWAN_CLOSED_WIPE_TOL = 1e-9

# params: [kt, fy, n_ref, memory (0 full, 1 last), max_depth]
# state : [q_prev, G_prev, a_prev, dir, base, base_q, base_a, m, base_G, (q_i, G_i, a_i) * max_depth]
#   base: 0 separated, 1 virgin (base_q = q_c), 2 saturated (base_q = q_s, base_a = alpha_s);
#   base_G: force offset of the base curve left by rejoins under varying alpha
_Q, _G, _A, _DIR, _BASE, _BQ, _BA, _M, _BG = 0, 1, 2, 3, 4, 5, 6, 7, 8
_HEAD = 9
_SEP, _VIRGIN, _SAT = 0.0, 1.0, 2.0
_SAT_RTOL = 1e-12
# a branch within this distance (normalised q, units of fy/kt) of an earlier
# reversal point has reached it: without it, rounding makes steady cycles
# stop a hair short of their own earlier reversal points, and the stack
# grows by one point every half cycle (memory of loops of size ~1e-16)
_WIPE_TOL = IWAN_CLOSED_WIPE_TOL


@jit(inline="always")
def _goa(u, a):
    """Normalised backbone G_oa(u; a) for u >= 0 and its partials (d/du, d/da)."""
    if u < 2.0 * a:
        h = 0.5 * u / a  # one division: G = u - u h / 2, dG/du = 1 - h, dG/da = h^2
        return u - 0.5 * u * h, 1.0 - h, h * h
    return a, 0.0, 1.0


@jit
def backbone(q, alpha):
    """Normalised virgin curve G_oa(q; alpha), odd in q (docs/model.md eq. of section 3).

    Parameters
    ----------
    q : float
        Normalised displacement kt x / fy.
    alpha : float
        Normal-load ratio N / N_ref (> 0).

    Returns
    -------
    float
        G = T / fy.
    """
    if q >= 0.0:
        return _goa(q, alpha)[0]
    return -_goa(-q, alpha)[0]


@jit(inline="always")
def _branch(s, m, base, d, q, alpha):
    """Force on the current branch and its partials.

    Returns ``G, cq, ca, c0q, c0g, c0a, rq, rg, ra``: the normalised force and
    the coefficients of dG = cq dq + ca dalpha + c0q dq_ref + c0g dG_ref +
    c0a dalpha_ref, where the reference quantities are state rows rq, rg, ra
    (the top reversal point (q0, G0, alpha0), or the base point with its
    force offset).
    """
    if m == 0:
        off = s[_BG]
        if base == _VIRGIN:
            u = q - s[_BQ]
            sg = 1.0 if u > 0.0 else (-1.0 if u < 0.0 else (d if d != 0.0 else 1.0))
            g, gu, ga = _goa(sg * u, alpha)
            return sg * g + off, gu, sg * ga, -gu, 1.0, 0.0, _BQ, _BG, _BA
        # saturated base, moving on in its direction
        asat = s[_BA]
        aeff = alpha - asat
        if aeff > 0.0:
            u = d * (q - s[_BQ])
            if u < 0.0:
                u = 0.0
            g, gu, ga = _goa(u, aeff)
            return d * asat + d * g + off, gu, d * ga, -gu, 1.0, d - d * ga, _BQ, _BG, _BA
        return d * alpha + off, 0.0, d, 0.0, 1.0, 0.0, _BQ, _BG, _BA
    ref = _HEAD + 3 * (m - 1)
    q0 = s[ref]
    g0 = s[ref + 1]
    a0 = s[ref + 2]
    # G = G0 + d c G_oa(v / c; alpha) with v = d (q - q0), c = 1 + a0/alpha,
    # simplifies to G0 + d (v - v^2 / (4 S)) for v < 2 S, G0 + d S beyond,
    # S = alpha + a0 = c alpha: one division instead of five
    v = d * (q - q0)
    if v < 0.0:
        v = 0.0
    S = alpha + a0
    if v < 2.0 * S:
        h = 0.5 * v / S  # = u / (2 alpha), u = v / c
        # dG/dalpha = dG/dalpha0 = d v^2 / (4 S^2)
        cq = 1.0 - h
        ca = d * h * h
        return g0 + d * (v - 0.5 * v * h), cq, ca, -cq, 1.0, ca, ref, ref + 1, ref + 2
    return g0 + d * S, 0.0, d, 0.0, 1.0, d, ref, ref + 1, ref + 2


# The trial step is split into the helpers below, each doing one job. Those
# on the path of every step (copy of the live state, rejoin test, branch
# force, saturation, derivatives) are inline="always" (inlined at the Numba
# IR level), so that each public kernel is one function small enough for LLVM
# to inline into the caller's time loop (a call passing three arrays field by
# field cost half of the step time). Those on rare paths (separation,
# re-contact, a reversal, a rejoin) are compiled apart and called: that keeps
# the inlined step small, and quick to compile into every loop that binds
# it. The derivative arguments (ds_old, ds_new, dx, dN, dT) are either all
# arrays or all None; Numba prunes the ``is not None`` branches at compile
# time, so the plain step carries no derivative code at all.


@jit
def _separate(s_new, x, alpha, kt, fy, n_ref, ds_new, dx, dN, dT, nd):
    """Open contact (alpha <= 0) or no friction (fy = 0): T = 0, memory lost.

    The state keeps q and alpha (so that the next step can detect motion);
    with alpha > 0 (no friction) the base curve is virgin and the code
    MACROSLIP, otherwise the base is separated and the code SEPARATION.
    """
    qs0 = kt / fy if fy > 0.0 else 0.0
    for r in range(_HEAD):
        s_new[r] = 0.0
    s_new[_Q] = qs0 * x
    s_new[_A] = alpha
    if ds_new is not None:
        for j in range(nd):
            for r in range(_HEAD):
                ds_new[r, j] = 0.0
            ds_new[_Q, j] = qs0 * dx[j]
            ds_new[_A, j] = dN[j] / n_ref
            dT[j] = 0.0
    if alpha > 0.0:
        s_new[_BASE] = _VIRGIN
        return 0.0, 0.0, MACROSLIP
    s_new[_BASE] = _SEP
    return 0.0, 0.0, SEPARATION


@jit
def _contact_start(s_new, q, alpha, kt, qs, ia, ds_new, dx, dN, dT, nd):
    """(Re)contact after separation: a virgin curve starts at q (T = 0, kT = kt)."""
    for r in range(_HEAD):
        s_new[r] = 0.0
    s_new[_Q] = q
    s_new[_A] = alpha
    s_new[_BASE] = _VIRGIN
    s_new[_BQ] = q
    if ds_new is not None:
        for j in range(nd):
            for r in range(_HEAD):
                ds_new[r, j] = 0.0
            ds_new[_Q, j] = qs * dx[j]
            ds_new[_A, j] = ia * dN[j]
            ds_new[_BQ, j] = qs * dx[j]
            dT[j] = 0.0
    return 0.0, kt, STICK_SLIP


@jit(inline="always")
def _copy_live(s_old, s_new, m, ds_old, ds_new, nd):
    """Copy the live part of the committed state: base point, its force offset
    and the m reversal points (rows _Q, _G, _A, _DIR, _BASE, _M are written at
    the end of the step); the derivative rows up to the stack top likewise."""
    s_new[_BQ] = s_old[_BQ]
    s_new[_BA] = s_old[_BA]
    s_new[_BG] = s_old[_BG]
    for r in range(_HEAD, _HEAD + 3 * m):
        s_new[r] = s_old[r]
    if ds_new is not None:
        for r in range(_HEAD + 3 * m):
            for j in range(nd):
                ds_new[r, j] = ds_old[r, j]


@jit
def _push_reversal(s_old, s_new, m, last_only, max_depth, ds_old, ds_new, nd):
    """Push the previous point (q, G, alpha of the committed state) onto the
    reversal stack: it becomes the only point under the last-reversal rule,
    and the innermost pair is forgotten when the stack is full. Returns the
    new depth."""
    if last_only:
        m = 0
    elif m >= max_depth:
        m -= 2  # forget the innermost pair (documented limitation)
    r = _HEAD + 3 * m
    s_new[r] = s_old[_Q]
    s_new[r + 1] = s_old[_G]
    s_new[r + 2] = s_old[_A]
    if ds_new is not None:
        for j in range(nd):
            ds_new[r, j] = ds_old[_Q, j]
            ds_new[r + 1, j] = ds_old[_G, j]
            ds_new[r + 2, j] = ds_old[_A, j]
    return m + 1


@jit(inline="always")
def _rejoin_point(s_new, m):
    """Where a branch of depth m >= 1 rejoins an earlier one: the reversal
    point below its own start (m >= 2), or the mirror point 2 q_c - q_0 of
    the virgin curve (m = 1)."""
    if m >= 2:
        return s_new[_HEAD + 3 * (m - 2)]
    return 2.0 * s_new[_BQ] - s_new[_HEAD]


@jit(inline="always")
def _reaches_rejoin(s_new, m, base, d, q):
    """Whether the current branch (depth m, direction d) has reached its
    rejoin point at q; a first branch rejoins the virgin curve only, never a
    saturated base."""
    if m >= 2 or (m == 1 and base == _VIRGIN):
        return d * (q - _rejoin_point(s_new, m)) >= -_WIPE_TOL
    return False


@jit
def _rejoin(s_new, m, base, d, q, alpha, ia, ds_new, dN, nd):
    """Masing's extended rules with the force-offset rule, once the current
    branch has reached its rejoin point; returns the stack depth left.

    The branch rejoins the one the point belonged to and both points are
    forgotten, as long as rejoin points are reached. The mismatch of the two
    branches at the rejoin point qt is added to the rejoined branch's
    reference force (its G0, or the base offset), so that T stays
    continuous; it is zero at constant alpha. Compiled apart (rare path):
    the step stays small for LLVM and quick to compile.
    """
    while True:
        qt = _rejoin_point(s_new, m)
        m_after = m - 2 if m >= 2 else 0
        gb, cqb, cab, c0qb, c0gb, c0ab, rqb, rgb, rab = _branch(s_new, m, base, d, qt, alpha)
        ga, cqa, caa, c0qa, c0ga, c0aa, rqa, rga, raa = _branch(s_new, m_after, base, d, qt, alpha)
        rg = _BG if m_after == 0 else _HEAD + 3 * (m_after - 1) + 1
        if ds_new is not None:
            for j in range(nd):
                if m >= 2:
                    dqj = ds_new[_HEAD + 3 * (m - 2), j]
                else:
                    dqj = 2.0 * ds_new[_BQ, j] - ds_new[_HEAD, j]
                daj = ia * dN[j]
                dgb = cqb * dqj + cab * daj + c0qb * ds_new[rqb, j] + c0gb * ds_new[rgb, j] + c0ab * ds_new[rab, j]
                dga = cqa * dqj + caa * daj + c0qa * ds_new[rqa, j] + c0ga * ds_new[rga, j] + c0aa * ds_new[raa, j]
                ds_new[rg, j] += dgb - dga
        s_new[rg] += gb - ga
        m = m_after
        if not _reaches_rejoin(s_new, m, base, d, q):
            return m


@jit(inline="always")
def _wipe_to_saturation(s_new, q, alpha, qs, ia, ds_new, dx, dN, nd):
    """Macroslip under full memory: every slider slips, so the reversal memory
    is wiped and the saturation point (q_s, alpha_s) = (q, alpha) becomes the
    base curve's reference, without force offset."""
    s_new[_BQ] = q
    s_new[_BA] = alpha
    s_new[_BG] = 0.0
    if ds_new is not None:
        for j in range(nd):
            ds_new[_BQ, j] = qs * dx[j]
            ds_new[_BA, j] = ia * dN[j]
            ds_new[_BG, j] = 0.0


@jit(inline="always")
def _propagate(ds_new, dT, fy, qs, ia, dx, dN, cq, ca, c0q, c0g, c0a, rq, rg, ra, nd):
    """Derivative of the step: dG = cq dq + ca dalpha + c0q dq_ref + c0g dG_ref
    + c0a dalpha_ref (reference rows rq, rg, ra), dT = fy dG, and the
    derivative of the committed point (q, G, alpha)."""
    for j in range(nd):
        dgj = (
            cq * qs * dx[j]
            + ca * ia * dN[j]
            + c0q * ds_new[rq, j]
            + c0g * ds_new[rg, j]
            + c0a * ds_new[ra, j]
        )
        dT[j] = fy * dgj
        ds_new[_Q, j] = qs * dx[j]
        ds_new[_G, j] = dgj
        ds_new[_A, j] = ia * dN[j]


@jit(inline="always")
def _closed_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    """Trial step with optional forward-mode derivatives (see the helpers)."""
    kt = params[0]
    fy = params[1]
    n_ref = params[2]
    last_only = params[3] != 0.0
    max_depth = int(params[4])
    alpha = N / n_ref
    nd = 0
    if dx is not None:
        nd = dx.shape[0]
    if alpha <= 0.0 or fy <= 0.0:
        return _separate(s_new, x, alpha, kt, fy, n_ref, ds_new, dx, dN, dT, nd)
    qs = kt / fy  # dq = qs * dx
    ia = 1.0 / n_ref  # dalpha = ia * dN
    q = qs * x
    if s_old[_BASE] == _SEP:
        return _contact_start(s_new, q, alpha, kt, qs, ia, ds_new, dx, dN, dT, nd)

    m = int(s_old[_M])
    _copy_live(s_old, s_new, m, ds_old, ds_new, nd)
    base = s_old[_BASE]
    d = s_old[_DIR]
    # reversal detection: moving against d makes the previous point a reversal point
    q_prev = s_old[_Q]
    if q != q_prev:
        dnew = 1.0 if q > q_prev else -1.0
        if d != 0.0 and dnew != d:
            m = _push_reversal(s_old, s_new, m, last_only, max_depth, ds_old, ds_new, nd)
        d = dnew
    # Masing's extended rules: rejoin earlier branches while they are reached
    if not last_only and _reaches_rejoin(s_new, m, base, d, q):
        m = _rejoin(s_new, m, base, d, q, alpha, ia, ds_new, dN, nd)

    # force on the current branch: G and the coefficients of its derivative
    G, cq, ca, c0q, c0g, c0a, rq, rg, ra = _branch(s_new, m, base, d, q, alpha)

    # clip (macroslip): |G| = alpha, no stiffness left
    code = STICK_SLIP
    if G >= alpha * (1.0 - _SAT_RTOL) or G <= -alpha * (1.0 - _SAT_RTOL):
        sg = 1.0 if G > 0.0 else -1.0
        G = sg * alpha
        code = MACROSLIP
        cq = 0.0
        c0q = 0.0
        c0g = 0.0
        c0a = 0.0
        ca = sg
        if not last_only:
            m = 0
            base = _SAT
            d = sg
            _wipe_to_saturation(s_new, q, alpha, qs, ia, ds_new, dx, dN, nd)

    if ds_new is not None:
        _propagate(ds_new, dT, fy, qs, ia, dx, dN, cq, ca, c0q, c0g, c0a, rq, rg, ra, nd)
    s_new[_Q] = q
    s_new[_G] = G
    s_new[_A] = alpha
    s_new[_DIR] = d
    s_new[_BASE] = base
    s_new[_M] = m
    return fy * G, kt * cq, code


# inline="always" (here and in the core): Numba inlines the kernel into the
# caller's compiled loop (march, integrators), where a call passing three
# arrays field by field cost about half of the step time
@jit(inline="always")
def closed_step(params, s_old, s_new, x, N):
    """Trial step of the closed-form Iwan law: the kernel contract's ``step``
    (:mod:`jointdyn.laws._base`: arguments, returns, units), with
    ``params = [kt (N/m), fy (N), N_ref (N), memory (0 full / 1 last), max_depth]``
    and states of length ``9 + 3 max_depth`` (module docstring); T from the
    paper's T-> / T<- (docs/model.md section 3).
    """
    return _closed_core(params, s_old, s_new, x, N, None, None, None, None, None)


@jit
def closed_init(params, x0, n0, s):
    """Virgin committed state at displacement ``x0`` (m) and normal load ``n0`` (N).

    q = (kt / fy) x0 (the kernels' expression, bit for bit: a rounding
    difference would look like motion and, under the paper's last-reversal
    rule, turn the virgin curve into a reversal branch), alpha = n0 / n_ref,
    base curve virgin (alpha > 0) or separated, empty reversal stack.
    """
    kt = params[0]
    fy = params[1]
    a = n0 / params[2]
    q = (kt / fy) * x0 if fy > 0.0 else 0.0
    s[:] = 0.0
    s[_Q] = q
    s[_A] = a
    s[_BASE] = _VIRGIN if a > 0.0 else _SEP
    s[_BQ] = q


@jit
def closed_init_jvp(params, x0, dx0, n0, dn0, s, ds):
    """:func:`closed_init` and its derivative along ``dx0.size`` directions.

    The virgin state is linear in x0 (rows q and the base point q_c) and in
    n0 (row alpha) on each side of n0 = 0; ``ds`` (state size, directions)
    receives d(state) = (kt/fy) dx0 on those two rows, dn0 / n_ref on alpha.
    """
    closed_init(params, x0, n0, s)
    qs = params[0] / params[1] if params[1] > 0.0 else 0.0
    ia = 1.0 / params[2]
    for r in range(ds.shape[0]):
        for j in range(ds.shape[1]):
            ds[r, j] = 0.0
    for j in range(ds.shape[1]):
        ds[_Q, j] = qs * dx0[j]
        ds[_BQ, j] = qs * dx0[j]
        ds[_A, j] = ia * dn0[j]


@jit
def closed_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
    """:func:`closed_step` with forward-mode derivatives along ``dx.size`` directions."""
    return _closed_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT)


@dataclass(frozen=True)
class IwanClosedForm(ContactLaw):
    """Closed-form Iwan law with slip forces scaled by N(t)/N_ref (the paper's model).

    Exact at constant normal load (``memory="full"``) but not when the load
    falls while the contact follows a branch (module docstring); the exact
    model is :class:`~jointdyn.Iwan`. Registered as ``iwan-closed``
    (``memory="full"``) and ``iwan-paper`` (``memory="last"``).

    Parameters
    ----------
    kt : float
        Total tangential stiffness, N/m.
    mu : float
        Friction coefficient; fy = mu n_ref is the macroslip force at N_ref.
    n_ref : float
        Reference normal load N_ref, N.
    memory : {"full", "last"}
        ``"full"``: Masing's extended rules (exact at constant N for any
        history); ``"last"``: the paper's last-reversal-only rule.
    max_depth : int
        Capacity of the reversal-point stack (>= 2). When full, the
        innermost pair of reversal points is forgotten.
    """

    memory: str = law_param(
        "full", choices=("full", "last"),
        help="reversal memory: full (Masing's extended rules) or last (the paper's last-reversal rule)",
    )
    max_depth: int = law_param(
        IWAN_CLOSED_MAX_DEPTH, low=2,
        help="capacity of the reversal-point stack (the innermost pair is forgotten when full)",
    )
    name: ClassVar[str] = "iwan-closed"
    kernels: ClassVar[tuple] = (closed_step, closed_step_jvp, closed_init, closed_init_jvp)

    @property
    def params(self) -> np.ndarray:
        return np.array(
            [self.kt, self.fy, self.n_ref, 0.0 if self.memory == "full" else 1.0, float(self.max_depth)]
        )

    @property
    def state_size(self) -> int:
        return _HEAD + 3 * self.max_depth

    @property
    def passive(self) -> bool:
        """Full memory only: the last-reversal rule can create energy after
        nested reversals (it forgets the outer loops)."""
        return self.memory == "full"

    @property
    def x_slip(self) -> float:
        """2 fy / kt (m): the virgin curve G_oa reaches macroslip at q = 2."""
        return 2.0 * self.fy / self.kt

    def _state_error(self, s):
        """The head and the live reversal points finite, the depth an integer
        in [0, max_depth], the base code and the direction valid (the stack
        rows beyond the depth are never read and may hold anything)."""
        head = s[:_HEAD]
        if not np.all(np.isfinite(head)):
            return f"entries 0..{_HEAD - 1} must be finite, got {head.tolist()}"
        m = s[_M]
        if not (m == int(m) and 0 <= m <= self.max_depth):
            return f"entry {_M} (reversal-stack depth) must be an integer in [0, {self.max_depth}], got {float(m)!r}"
        if s[_BASE] not in (_SEP, _VIRGIN, _SAT):
            return f"entry {_BASE} (base curve) must be 0, 1 or 2, got {float(s[_BASE])!r}"
        if s[_DIR] not in (-1.0, 0.0, 1.0):
            return f"entry {_DIR} (direction) must be -1, 0 or 1, got {float(s[_DIR])!r}"
        live = s[_HEAD : _HEAD + 3 * int(m)]
        if not np.all(np.isfinite(live)):
            return f"the {int(m)} live reversal points (entries {_HEAD}..{_HEAD + 3 * int(m) - 1}) must be finite"
        return None


register(
    "iwan-closed", IwanClosedForm, fixed={"memory": "full"},
    summary="closed-form Iwan with full Masing memory: exact at constant N for any history, "
    "misses slip caused by a falling N within a branch",
    label="closed-form Iwan, full memory",
)
register(
    "iwan-paper", IwanClosedForm, fixed={"memory": "last"},
    summary="closed-form Iwan with the paper's last-reversal rule (Li & Xu)",
    label="closed-form Iwan, paper's last-reversal rule",
)
