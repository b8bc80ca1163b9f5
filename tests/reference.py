"""Slow plain-Python reference implementations of the contact laws.

Written from docs/model.md (sections 2-5) and the module docstring of
``jointdyn.laws.iwan_closed``, independently of the compiled kernels' structure
(no state vectors, no numba, no numpy): objects that hold their memory as
Python lists and commit on every call of :meth:`step` (the exact Iwan law's
reference, written from ``jointdyn.laws.exact``, is in ``reference_exact.py``).
They are oracles for
the tests (``test_laws_reference.py``) and the pure-Python baseline of
``benchmarks/bench_laws.py``.

Each reference has ``step(x, N) -> (T, kT, code)`` (x in m, N in N, T in N,
kT = dT/dx at fixed N in N/m, code 0 stick-slip, 1 macroslip, 2 separation)
and is constructed in the law's virgin state at ``(x0, n0)``, the state
``law.initial_state(x0, n0)`` describes, so ``march_ref(ref, x, N)`` is
comparable with ``jointdyn.march(law, x, N)``.
"""

from __future__ import annotations

from reference_exact import ExactIwanRef
from reference_segalman import SegalmanRef

STICK_SLIP, MACROSLIP, SEPARATION = 0, 1, 2

#: a branch value with |G| >= alpha (1 - SAT_RTOL) counts as macroslip (the
#: closed form reaches |G| = alpha only up to rounding); the same threshold
#: as the compiled law, documented there as part of the clip
SAT_RTOL = 1e-12
#: a branch within this distance (normalised q) of an earlier reversal point
#: has reached it (Masing rejoin): the tolerance documented in laws/iwan_closed.py
WIPE_TOL = 1e-9


def goa(u, a):
    """Normalised backbone G_oa(u; a) for u >= 0 and its slope dG/du (docs/model.md s. 3)."""
    if u < 2.0 * a:
        return u - u * u / (4.0 * a), 1.0 - u / (2.0 * a)
    return a, 0.0


def _sign(v):
    return 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)


class DiscreteIwanRef:
    """n Jenkins elements, docs/model.md section 5, one element at a time.

    Element i: stiffness kt/n, slip force alpha f_i / n with f_i the midpoint
    of the i-th of n equal bins of [0, 2 fy].
    """

    def __init__(self, kt, mu, n_ref, n, x0=0.0, n0=None):
        self.kt = float(kt)
        self.fy = float(mu) * float(n_ref)
        self.n_ref = float(n_ref)
        self.n = int(n)
        self.f = [2.0 * self.fy * (i + 0.5) / self.n for i in range(self.n)]
        self.p = [0.0] * self.n
        self.x_prev = float(x0)

    def step(self, x, N):
        alpha = N / self.n_ref
        ke = self.kt / self.n
        dx = x - self.x_prev
        self.x_prev = x
        if alpha <= 0.0:
            self.p = [0.0] * self.n
            return 0.0, 0.0, SEPARATION
        total = 0.0
        sticking = 0
        for i in range(self.n):
            trial = self.p[i] + ke * dx
            limit = alpha * self.f[i] / self.n
            if abs(trial) > limit:
                trial = limit if trial > 0.0 else -limit
            else:
                sticking += 1
            self.p[i] = trial
            total += trial
        return total, ke * sticking, (STICK_SLIP if sticking else MACROSLIP)


class IwanRef:
    """Closed-form Iwan law with full Masing memory (``IwanClosedForm(memory="full")``).

    Memory (laws/iwan_closed.py docstring): a stack of reversal points
    ``(q, G, alpha)``; the current branch starts at the top one. Below the
    stack lies the *base*: the virgin curve from the contact point q_c, or
    the saturation point (q_s, alpha_s) of the last macroslip.

    * reversal: when the direction of q changes, the previous point is pushed
      (if the stack is full, its two innermost points are dropped first);
    * wipe (Masing's extended rules): a branch that reaches the reversal
      point below its own start rejoins the branch that point belonged to,
      and both points are forgotten; a first branch on the virgin curve
      rejoins the virgin curve at the mirror point 2 q_c - q_0;
    * clip: |G| >= alpha means every slider slips: G = +-alpha, memory wiped,
      base = saturation point (q, alpha) and direction = sign of G;
    * saturated base, moving on: G = d alpha_s + d G_oa(|q - q_s|; alpha - alpha_s)
      (sliders re-stick when alpha rises), G = d alpha if alpha <= alpha_s;
    * separation (alpha <= 0): T = 0 and everything is forgotten; the first
      contact point starts a virgin curve (T = 0, kT = kt there).
    """

    last_only = False

    def __init__(self, kt, mu, n_ref, x0=0.0, n0=None, max_depth=64):
        self.kt = float(kt)
        self.fy = float(mu) * float(n_ref)
        self.n_ref = float(n_ref)
        self.max_depth = int(max_depth)
        a = 1.0 if n0 is None else float(n0) / self.n_ref
        q = self.kt * x0 / self.fy if self.fy > 0.0 else 0.0
        self.q_last, self.G_last, self.a_last = q, 0.0, a
        self.direction = 0.0
        self.stack = []
        self.base = "virgin" if a > 0.0 else "separated"
        self.q_base = q  # q_c (virgin) or q_s (saturated)
        self.a_base = 0.0  # alpha_s (saturated)
        self.g_base = 0.0  # force offset of the base curve (rejoins under varying alpha)

    def _branch(self, q, alpha, d):
        """Force and slope of the current branch (top reversal point or base)."""
        if self.stack:
            q0, G0, a0 = self.stack[-1]
            c = 1.0 + a0 / alpha
            u = max(0.0, d * (q - q0) / c)
            g, slope = goa(u, alpha)
            return G0 + d * c * g, slope
        if self.base == "virgin":
            u = q - self.q_base
            g, slope = goa(abs(u), alpha)
            return _sign(u) * g + self.g_base, slope
        a_extra = alpha - self.a_base  # saturated base
        if a_extra > 0.0:
            g, slope = goa(max(0.0, d * (q - self.q_base)), a_extra)
            return d * self.a_base + d * g + self.g_base, slope
        return d * alpha + self.g_base, 0.0

    def _forget(self, q, alpha):
        self.stack = []
        self.direction = 0.0
        self.g_base = 0.0
        self.q_last, self.G_last, self.a_last = q, 0.0, alpha

    def step(self, x, N):
        alpha = N / self.n_ref
        if self.fy <= 0.0:  # no friction: never any force
            return 0.0, 0.0, (MACROSLIP if alpha > 0.0 else SEPARATION)
        q = self.kt * x / self.fy
        if alpha <= 0.0:
            self._forget(q, alpha)
            self.base = "separated"
            return 0.0, 0.0, SEPARATION
        if self.base == "separated":  # re-contact: virgin curve from here
            self._forget(q, alpha)
            self.base = "virgin"
            self.q_base = q
            return 0.0, self.kt, STICK_SLIP

        # reversal detection
        if q != self.q_last:
            moving = 1.0 if q > self.q_last else -1.0
            if self.direction == 0.0:
                self.direction = moving
            elif moving != self.direction:
                point = (self.q_last, self.G_last, self.a_last)
                if self.last_only:
                    self.stack = [point]
                else:
                    if len(self.stack) >= self.max_depth:
                        del self.stack[-2:]
                    self.stack.append(point)
                self.direction = moving
        d = self.direction

        # Masing's extended rules; a rejoin keeps T continuous by adding the
        # difference (zero at constant alpha) to the rejoined branch
        if not self.last_only:
            while True:
                if len(self.stack) >= 2 and d * (q - self.stack[-2][0]) >= -WIPE_TOL:
                    q_t = self.stack[-2][0]
                    before = self._branch(q_t, alpha, d)[0]
                    del self.stack[-2:]
                elif (
                    len(self.stack) == 1
                    and self.base == "virgin"
                    and d * (q - (2.0 * self.q_base - self.stack[0][0])) >= -WIPE_TOL
                ):
                    q_t = 2.0 * self.q_base - self.stack[0][0]
                    before = self._branch(q_t, alpha, d)[0]
                    self.stack = []
                else:
                    break
                # mismatch of the two branches at the rejoin point q_t
                jump = before - self._branch(q_t, alpha, d)[0]
                if self.stack:
                    q0, G0, a0 = self.stack[-1]
                    self.stack[-1] = (q0, G0 + jump, a0)
                else:
                    self.g_base += jump

        G, slope = self._branch(q, alpha, d)

        code = STICK_SLIP
        if abs(G) >= alpha * (1.0 - SAT_RTOL):
            sg = 1.0 if G > 0.0 else -1.0
            G, slope, code = sg * alpha, 0.0, MACROSLIP
            if not self.last_only:
                self.stack = []
                self.base = "saturated"
                self.q_base, self.a_base, self.g_base = q, alpha, 0.0
                self.direction = sg

        self.q_last, self.G_last, self.a_last = q, G, alpha
        return self.fy * G, self.kt * slope, code


class IwanPaperRef:
    """The paper's last-reversal rule (``IwanClosedForm(memory="last")``), written alone.

    Only the last reversal point (q0, G0, alpha0) is kept::

        G = G0 + d c G_oa(|q - q0| / c; alpha),  c = 1 + alpha0 / alpha,

    clipped to |G| <= alpha at every step; before the first reversal (and
    after every re-contact) the virgin curve G_oa(q - q_c; alpha).
    """

    def __init__(self, kt, mu, n_ref, x0=0.0, n0=None):
        self.kt = float(kt)
        self.fy = float(mu) * float(n_ref)
        self.n_ref = float(n_ref)
        a = 1.0 if n0 is None else float(n0) / self.n_ref
        q = self.kt * x0 / self.fy if self.fy > 0.0 else 0.0
        self.in_contact = a > 0.0
        self.q_c = q
        self.rev = None
        self.direction = 0.0
        self.q_last, self.G_last, self.a_last = q, 0.0, a

    def step(self, x, N):
        alpha = N / self.n_ref
        if self.fy <= 0.0:
            return 0.0, 0.0, (MACROSLIP if alpha > 0.0 else SEPARATION)
        q = self.kt * x / self.fy
        if alpha <= 0.0 or not self.in_contact:
            self.in_contact = alpha > 0.0
            self.q_c, self.rev, self.direction = q, None, 0.0
            self.q_last, self.G_last, self.a_last = q, 0.0, alpha
            if alpha <= 0.0:
                return 0.0, 0.0, SEPARATION
            return 0.0, self.kt, STICK_SLIP
        if q != self.q_last:
            moving = 1.0 if q > self.q_last else -1.0
            if self.direction != 0.0 and moving != self.direction:
                self.rev = (self.q_last, self.G_last, self.a_last)
            self.direction = moving
        d = self.direction
        if self.rev is None:
            g, slope = goa(abs(q - self.q_c), alpha)
            G = _sign(q - self.q_c) * g
        else:
            q0, G0, a0 = self.rev
            c = 1.0 + a0 / alpha
            g, slope = goa(max(0.0, d * (q - q0) / c), alpha)
            G = G0 + d * c * g
        code = STICK_SLIP
        if abs(G) >= alpha * (1.0 - SAT_RTOL):
            G, slope, code = (alpha if G > 0.0 else -alpha), 0.0, MACROSLIP
        self.q_last, self.G_last, self.a_last = q, G, alpha
        return self.fy * G, self.kt * slope, code


#: registered law name -> factory(law, x0, n0) of its plain-Python reference;
#: every law in ``jointdyn.laws.law_names()`` needs an entry (the reference
#: comparison fails for a law without one)
REFERENCES = {
    "iwan": lambda law, x0, n0: ExactIwanRef(law.kt, law.mu, law.n_ref, law.capacity, x0, n0),
    "iwan-closed": lambda law, x0, n0: IwanRef(law.kt, law.mu, law.n_ref, x0, n0, max_depth=law.max_depth),
    "iwan-paper": lambda law, x0, n0: IwanPaperRef(law.kt, law.mu, law.n_ref, x0, n0),
    "discrete": lambda law, x0, n0: DiscreteIwanRef(law.kt, law.mu, law.n_ref, law.n, x0, n0),
    "jenkins": lambda law, x0, n0: DiscreteIwanRef(law.kt, law.mu, law.n_ref, 1, x0, n0),
    "segalman": lambda law, x0, n0: SegalmanRef(law.kt, law.mu, law.n_ref, law.chi, law.beta, law.capacity, x0, n0),
}


def reference_for(name, law, x0=0.0, n0=None):
    """The reference object equivalent to the registered law ``name`` (instance
    ``law``), in its virgin state at ``(x0, n0)``."""
    if name not in REFERENCES:
        raise LookupError(
            f"no plain-Python reference for the registered law {name!r}: write one in tests/reference.py "
            "(from the law's specification, not from its kernels) and add it to REFERENCES"
        )
    return REFERENCES[name](law, x0, n0)


def march_ref(ref, x, N):
    """Step ``ref`` through the samples; lists T (N), kT (N/m), code."""
    T, kT, code = [], [], []
    for xi, ni in zip(x, N):
        t, k, c = ref.step(float(xi), float(ni))
        T.append(t)
        kT.append(k)
        code.append(c)
    return T, kT, code
