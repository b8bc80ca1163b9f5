"""Compiled march of a contact law over a prescribed history."""

from __future__ import annotations

import numpy as np

from .. import _validate as V
from .._jit import specialize
from ..laws import ContactLaw

__all__ = ["march"]


def _march_template(params, s0, x, N, T, kT, code, s_final):  # pragma: no cover - compiled
    """March ``STEP`` over samples ``x[i], N[i]``, committing after each."""
    a = s0.copy()
    b = s0.copy()  # unused stack rows stay finite in the returned state
    for i in range(x.shape[0]):
        t_, k_, c_ = STEP(params, a, b, x[i], N[i])  # noqa: F821 - bound by specialize
        T[i] = t_
        kT[i] = k_
        code[i] = c_
        a, b = b, a
    # element by element: a slice assignment compiles numba's shape-mismatch
    # error message (string formatting, about 1.5 s of cold compile)
    for r in range(a.shape[0]):
        s_final[r] = a[r]


def march(law, x, N, state=None):
    """Force history of ``law`` for displacement and normal-load samples.

    Parameters
    ----------
    law : ContactLaw
        Any registered contact law (:func:`jointdyn.make_law`).
    x : ndarray
        Tangential displacement samples, m.
    N : ndarray
        Normal-load samples, N (same length).
    state : ndarray, optional
        Committed state to start from (validated by ``law.check_state``);
        default the law's virgin state at ``x[0], N[0]``.

    Raises
    ------
    ValueError
        If ``law`` is not a contact law, if ``x`` or ``N`` is empty, not 1-D
        or not finite, if their lengths differ, or if ``state`` is not an
        admissible state of ``law`` (shape ``(law.state_size,)``, finite
        live part, law-specific fields valid).

    Returns
    -------
    T, kT, code, state : ndarray, ndarray, ndarray(int8), ndarray
        Force (N), tangent (N/m), motion state per sample, final state.
    """
    if not isinstance(law, ContactLaw):
        raise ValueError(
            f"law must be a ContactLaw (e.g. jointdyn.Iwan or jointdyn.make_law(name, ...)), "
            f"got {law!r} ({type(law).__name__})"
        )
    x = V.finite_array("x", x)
    N = V.finite_array("N", N)
    V.same_length(x=x, N=N)
    if state is None:
        s0 = law.initial_state(float(x[0]), float(N[0]))
    else:
        s0 = law.check_state(state)
    return _march_unchecked(law, x, N, s0)


def _march_unchecked(law, x, N, s0, params=None):
    """:func:`march` without input validation, for histories the package built
    itself (float64, finite, equal lengths; ``s0`` a valid state)."""
    n = x.shape[0]
    T = np.empty(n)
    kT = np.empty(n)
    code = np.empty(n, dtype=np.int8)
    s_final = np.empty_like(s0)
    p = law.params if params is None else params
    specialize(_march_template, STEP=law.step)(p, s0, x, N, T, kT, code, s_final)
    return T, kT, code, s_final


def law_marcher(step):
    """The compiled march of a law kernel over a history, for compiled loops.

    Returns ``marcher(params, s0, x, N, T, kT, code, s_final)``: steps the
    kernel ``step`` over the samples ``x[i]`` (m), ``N[i]`` (N) from the
    committed state ``s0`` (not written), committing after each, into the
    force ``T`` (N), tangent ``kT`` (N/m) and motion state ``code`` (int8)
    per sample and the final state ``s_final`` (no validation; the same
    compiled loop as :func:`march`). Templates that march a law over a
    history bind it as a placeholder (e.g. ``MARCH``) with
    :func:`jointdyn._jit.specialize`.
    """
    return specialize(_march_template, STEP=step)
