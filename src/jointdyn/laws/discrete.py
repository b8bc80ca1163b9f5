"""Discrete Iwan model: n parallel Jenkins elements (docs/model.md section 5).

The ground truth of jointdyn: exact for any history (Masing memory is
automatic) and any normal-load variation. ``n = 1`` is a single Jenkins
element whose slip force follows the normal load (Yang-Menq contact).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import config
from .. import _validate as V
from .._jit import jit
from ._base import MACROSLIP, SEPARATION, STICK_SLIP, ContactLaw, law_param, register

__all__ = ["DiscreteIwan", "Jenkins", "discrete_step", "discrete_step_jvp", "discrete_init", "discrete_init_jvp",
           "jenkins_step", "jenkins_step_jvp", "DiscreteElements", "elements_step", "elements_step_jvp"]

# params layout: [kt, fy, n_ref, n, f_1 ... f_n]  (f_i: total slip force of
# element i at the reference load, i.e. element limit = alpha * f_i / n)
# state layout:  [x_prev, p_1 ... p_n]            (p_i: element force, N)
_P_HEAD = 4
_S_HEAD = 1


@jit(inline="always")
def _lane_sum(a, lo, hi):
    """sum(a[lo:hi]) in eight interleaved partial sums, combined pairwise.

    Eight independent accumulators break the add latency chain (the loop
    is throughput-bound instead of latency-bound) without ``fastmath``;
    the summation order is fixed, so every caller gets the same bits.
    """
    n8 = lo + (hi - lo) // 8 * 8
    t0 = t1 = t2 = t3 = t4 = t5 = t6 = t7 = 0.0
    for i in range(lo, n8, 8):
        t0 += a[i]
        t1 += a[i + 1]
        t2 += a[i + 2]
        t3 += a[i + 3]
        t4 += a[i + 4]
        t5 += a[i + 5]
        t6 += a[i + 6]
        t7 += a[i + 7]
    t = ((t0 + t1) + (t2 + t3)) + ((t4 + t5) + (t6 + t7))
    for i in range(n8, hi):
        t += a[i]
    return t


@jit(inline="always")
def _start(s_new, x, alpha, n, ds_new, dx, dT):
    """The start of a step of n elements at load ratio ``alpha``: ``x_prev`` (and its derivatives) set
    to x, ``dT`` zeroed, and where ``alpha <= 0`` (separation) every element force and its derivatives
    zeroed. Returns the number of directions."""
    nd = 0
    if dx is not None:
        nd = dx.shape[0]
    s_new[0] = x
    if ds_new is not None:
        for j in range(nd):
            ds_new[0, j] = dx[j]
            dT[j] = 0.0
    if alpha <= 0.0:
        for i in range(n):
            s_new[_S_HEAD + i] = 0.0
        if ds_new is not None:
            for i in range(n):
                for j in range(nd):
                    ds_new[_S_HEAD + i, j] = 0.0
    return nd


@jit
def _discrete_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    # Derivative arguments are all arrays or all None (pruned at compile time).
    # Not inlined into callers: as a function of its own, the element loop
    # below compiles to SIMD code (AVX-512 where available); inlined into a
    # time loop it did not vectorise.
    kt = params[0]
    n_ref = params[2]
    n = int(params[3])
    alpha = N / n_ref
    nd = _start(s_new, x, alpha, n, ds_new, dx, dT)
    if alpha <= 0.0:
        return 0.0, 0.0, SEPARATION
    ke = kt / n
    inc = ke * (x - s_old[0])
    scale = alpha / n
    # element loop, branch-free so that it vectorises: trial force, clamp to
    # +-limit with max/min, count the elements the clamp left alone (stuck)
    nstick = 0
    for i in range(n):
        lim = scale * params[_P_HEAD + i]
        p = s_old[_S_HEAD + i] + inc
        pc = min(max(p, -lim), lim)
        s_new[_S_HEAD + i] = pc
        nstick += pc == p
    T = _lane_sum(s_new, _S_HEAD, _S_HEAD + n)
    if ds_new is not None:
        for i in range(n):
            r = _S_HEAD + i
            p = s_new[r]
            if p == s_old[r] + inc:  # stuck: same test as above, same bits
                for j in range(nd):
                    dp = ds_old[r, j] + ke * (dx[j] - ds_old[0, j])
                    ds_new[r, j] = dp
                    dT[j] += dp
            else:
                c = (1.0 if p > 0.0 else -1.0) * params[_P_HEAD + i] / (n * n_ref)
                for j in range(nd):
                    dp = c * dN[j]
                    ds_new[r, j] = dp
                    dT[j] += dp
    code = MACROSLIP if nstick == 0 else STICK_SLIP
    return T, ke * nstick, code


@jit(inline="always")
def _single_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    """:func:`_discrete_core` for one element (n = 1, a Jenkins element), the same operations in the same
    order (the same bits), inlined into the kernels: a call of the element loop costs more than the step
    of one element (about 90 ns against 40 ns per step with it inlined)."""
    kt = params[0]
    n_ref = params[2]
    alpha = N / n_ref
    nd = _start(s_new, x, alpha, 1, ds_new, dx, dT)
    if alpha <= 0.0:
        return 0.0, 0.0, SEPARATION
    ke = kt / 1
    inc = ke * (x - s_old[0])
    lim = (alpha / 1) * params[_P_HEAD]
    p = s_old[_S_HEAD] + inc
    pc = min(max(p, -lim), lim)
    s_new[_S_HEAD] = pc
    stuck = pc == p
    if ds_new is not None:
        if stuck:
            for j in range(nd):
                dp = ds_old[_S_HEAD, j] + ke * (dx[j] - ds_old[0, j])
                ds_new[_S_HEAD, j] = dp
                dT[j] += dp
        else:
            c = (1.0 if pc > 0.0 else -1.0) * params[_P_HEAD] / (1 * n_ref)
            for j in range(nd):
                dp = c * dN[j]
                ds_new[_S_HEAD, j] = dp
                dT[j] += dp
    if stuck:
        return 0.0 + pc, ke * 1, STICK_SLIP
    return 0.0 + pc, ke * 0, MACROSLIP


@jit
def discrete_step(params, s_old, s_new, x, N):
    """Trial step of n Jenkins elements with load-scaled slip forces: the kernel
    contract's ``step`` (:mod:`jointdyn.laws._base`: arguments, returns, units).

    Implements docs/model.md section 5: for each element, trial force
    ``p_i + (kt/n) dx``, clipped to ``alpha f_i / n`` with
    ``alpha = N / N_ref``; all ``p_i = 0`` when ``alpha <= 0``.
    ``params = [kt (N/m), fy (N), N_ref (N), n, f_1..f_n (N)]``, states
    ``[x_prev (m), p_1..p_n (N)]``; kT sums the sticking elements' kt / n;
    MACROSLIP when every element slips.
    """
    return _discrete_core(params, s_old, s_new, x, N, None, None, None, None, None)


@jit
def discrete_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
    """``discrete_step`` with forward-mode derivatives along ``dx.size`` directions.

    A sticking element carries ``dp_i = dp_i_old + (kt/n)(dx - dx_prev)``;
    a slipping one ``dp_i = sign(p_i) f_i dN / (n N_ref)``; separation zeroes
    everything. ``ds_*`` rows follow the state layout.
    """
    return _discrete_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT)


@jit
def jenkins_step(params, s_old, s_new, x, N):
    """:func:`discrete_step` of one element (``n = 1``), the same bits, with the element inlined."""
    return _single_core(params, s_old, s_new, x, N, None, None, None, None, None)


@jit
def jenkins_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
    """:func:`discrete_step_jvp` of one element (``n = 1``), the same bits, with the element inlined."""
    return _single_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT)


@jit
def discrete_init(params, x0, n0, s):
    """Virgin committed state at displacement ``x0`` (m): every element
    unstretched there (element forces zero); ``n0`` does not enter."""
    s[:] = 0.0
    s[0] = x0


@jit
def discrete_init_jvp(params, x0, dx0, n0, dn0, s, ds):
    """:func:`discrete_init` and its derivative: d(x_prev) = dx0, the
    element forces stay zero (``ds`` is (state size, directions))."""
    discrete_init(params, x0, n0, s)
    for r in range(ds.shape[0]):
        for j in range(ds.shape[1]):
            ds[r, j] = 0.0
    for j in range(ds.shape[1]):
        ds[0, j] = dx0[j]


@dataclass(frozen=True)
class DiscreteIwan(ContactLaw):
    """n parallel Jenkins elements, slip forces scaled by N(t)/N_ref.

    Element i has stiffness kt/n and slip force alpha(t) f_i / n, with f_i at
    the midpoints of n equal bins of [0, 2 fy] (uniform slip density, the
    discrete counterpart of :class:`~jointdyn.Iwan`). Exact for any history.

    Parameters
    ----------
    kt : float
        Total tangential stiffness, N/m.
    mu : float
        Friction coefficient.
    n_ref : float
        Reference normal load, N.
    n : int
        Number of Jenkins elements (>= 1). ``n = 1`` is one Jenkins element
        with slip force mu N(t) (use :class:`Jenkins`).
    """

    n: int = law_param(config.LAW_DISCRETE_N, low=1, help="number of Jenkins elements")
    name: ClassVar[str] = "discrete"
    kernels: ClassVar[tuple] = (discrete_step, discrete_step_jvp, discrete_init, discrete_init_jvp)

    @property
    def params(self) -> np.ndarray:
        n = self.n
        f = 2.0 * self.fy * (np.arange(n) + 0.5) / n
        return np.concatenate(([self.kt, self.fy, self.n_ref, float(n)], f))

    @property
    def state_size(self) -> int:
        return _S_HEAD + self.n

    @property
    def x_slip(self) -> float:
        """Slip displacement of the strongest element, 2 fy (n - 1/2) / (n kt) (m):
        the whole virgin curve is in macroslip beyond it."""
        return 2.0 * self.fy * (self.n - 0.5) / (self.n * self.kt)


@dataclass(frozen=True)
class Jenkins(DiscreteIwan):
    """One Jenkins element (spring kt in series with a slider mu N(t)).

    The Yang-Menq contact with the normal load prescribed; equals
    ``DiscreteIwan(n=1)``, bit for bit, with kernels of its own
    (:func:`jenkins_step`, :func:`jenkins_step_jvp`: the one element
    inlined).
    """

    n: int = 1
    name: ClassVar[str] = "jenkins"
    kernels: ClassVar[tuple] = (jenkins_step, jenkins_step_jvp, discrete_init, discrete_init_jvp)

    def __post_init__(self) -> None:
        if isinstance(self.n, bool) or self.n != 1:
            raise ValueError(f"n must be 1 for a Jenkins element (allowed range [1, 1]), got {self.n!r}")
        object.__setattr__(self, "n", 1)
        super().__post_init__()


# --- any density: element stiffnesses and slip forces given ------------------------------
# params layout: [kt, fy, n_ref, n, g_1 ... g_n, k_1 ... k_n]  (g_i: slip force of element i at
# the reference load, N; k_i: its stiffness, N/m); state layout as DiscreteIwan's


@jit
def _elements_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    # DiscreteIwan's element loop with a stiffness and a slip force per element
    n_ref = params[2]
    n = int(params[3])
    alpha = N / n_ref
    nd = _start(s_new, x, alpha, n, ds_new, dx, dT)
    if alpha <= 0.0:
        return 0.0, 0.0, SEPARATION
    dxs = x - s_old[0]
    kstick = 0.0
    nstick = 0
    for i in range(n):
        ke = params[_P_HEAD + n + i]
        lim = alpha * params[_P_HEAD + i]
        p = s_old[_S_HEAD + i] + ke * dxs
        pc = min(max(p, -lim), lim)
        s_new[_S_HEAD + i] = pc
        stuck = pc == p
        nstick += stuck
        kstick += ke if stuck else 0.0
    T = _lane_sum(s_new, _S_HEAD, _S_HEAD + n)
    if ds_new is not None:
        for i in range(n):
            r = _S_HEAD + i
            ke = params[_P_HEAD + n + i]
            p = s_new[r]
            if p == s_old[r] + ke * dxs:  # stuck: same test as above, same bits
                for j in range(nd):
                    dp = ds_old[r, j] + ke * (dx[j] - ds_old[0, j])
                    ds_new[r, j] = dp
                    dT[j] += dp
            else:
                c = (1.0 if p > 0.0 else -1.0) * params[_P_HEAD + i] / n_ref
                for j in range(nd):
                    dp = c * dN[j]
                    ds_new[r, j] = dp
                    dT[j] += dp
    code = MACROSLIP if nstick == 0 else STICK_SLIP
    return T, kstick, code


@jit
def elements_step(params, s_old, s_new, x, N):
    """Trial step of n Jenkins elements with given stiffnesses k_i (N/m) and slip
    forces alpha g_i (N): :func:`discrete_step` with any density.

    ``params = [kt, fy, N_ref, n, g_1..g_n, k_1..k_n]``; state and returns as
    :func:`discrete_step` (kT: sum of the stiffnesses of the stuck elements).
    """
    return _elements_core(params, s_old, s_new, x, N, None, None, None, None, None)


@jit
def elements_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
    """:func:`elements_step` with forward-mode derivatives along ``dx.size`` directions."""
    return _elements_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT)


def _element_array(name, values):
    """``values`` as a 1-D float64 array of finite positive numbers; ValueError naming ``name``."""
    try:
        a = np.array(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a 1-D array of positive numbers, got {type(values).__name__}") from None
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D array of positive numbers, got shape {a.shape}")
    bad = ~(np.isfinite(a) & (a > 0.0))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name} must hold finite numbers in (0, inf); entry {i} is {float(a[i])!r}")
    return a


@dataclass(frozen=True)
class DiscreteElements(ContactLaw):
    """Jenkins elements in parallel with given stiffnesses and slip forces (any density).

    Element i has stiffness ``stiffnesses[i]`` (N/m) and slip force
    ``alpha(t) slip_forces[i]`` (N, given at N_ref): a measured pressure
    distribution or a fitted slip-force density used directly. kt is the sum
    of the stiffnesses and mu = (sum of the slip forces) / n_ref. Build it
    with :meth:`from_elements`; not registered by name (its parameters are
    arrays). Exact for any history, as :class:`DiscreteIwan`.
    """

    stiffnesses: tuple = ()
    slip_forces: tuple = ()
    name: ClassVar[str] = "discrete-elements"
    kernels: ClassVar[tuple] = (elements_step, elements_step_jvp, discrete_init, discrete_init_jvp)

    @classmethod
    def from_elements(cls, stiffnesses, slip_forces, n_ref: float) -> "DiscreteElements":
        """The law of elements with stiffnesses ``stiffnesses`` (N/m, > 0) and slip forces
        ``slip_forces`` (N at ``n_ref``, > 0), arrays of the same length.

        Raises
        ------
        ValueError
            Naming the argument: not a 1-D array of finite positive numbers, or
            lengths that differ.
        """
        k = _element_array("stiffnesses", stiffnesses)
        f = _element_array("slip_forces", slip_forces)
        if k.size != f.size:
            raise ValueError(f"slip_forces must have the length of stiffnesses ({k.size}), got {f.size}")
        n_ref = V.positive("n_ref", n_ref)
        return cls(kt=float(k.sum()), mu=float(f.sum()) / n_ref, n_ref=n_ref,
                   stiffnesses=tuple(k.tolist()), slip_forces=tuple(f.tolist()))

    def __post_init__(self) -> None:
        super().__post_init__()
        if len(self.stiffnesses) == 0 or len(self.stiffnesses) != len(self.slip_forces):
            raise ValueError("stiffnesses and slip_forces must be non-empty and of one length "
                             "(build the law with DiscreteElements.from_elements)")
        _element_array("stiffnesses", self.stiffnesses)
        _element_array("slip_forces", self.slip_forces)

    @property
    def n(self) -> int:
        """Number of elements."""
        return len(self.stiffnesses)

    @property
    def params(self) -> np.ndarray:
        return np.concatenate(([self.kt, self.fy, self.n_ref, float(self.n)], self.slip_forces, self.stiffnesses))

    @property
    def state_size(self) -> int:
        return _S_HEAD + self.n

    @property
    def x_slip(self) -> float:
        """Largest slip displacement of an element, max(g_i / k_i) (m)."""
        return float(np.max(np.divide(self.slip_forces, self.stiffnesses)))


register("discrete", DiscreteIwan, summary="n Jenkins elements in parallel, the exact discrete Iwan model and ground truth",
         label="discrete Iwan")
register("jenkins", Jenkins, summary="one Jenkins element: spring kt in series with a slider mu N", label="Jenkins element")
