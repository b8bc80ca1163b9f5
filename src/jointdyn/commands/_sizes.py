"""Sizes set by harmonic-balance options, bounded by the memory before computing.

``--harmonics`` and ``--samples`` (``frc --method hb``, ``modes --method
epmc``) set the arrays of the harmonic balance: its Jacobians (the unknowns
squared), the synthesis and analysis matrices of the AFT (samples times
harmonics) and the contact states with their derivatives along every
harmonic. Their memory is estimated from the sizes and compared with
:func:`jointdyn._validate.memory_budget`; the option that sets the size is
named (``--harmonics`` first, with the fewest samples it needs, so that a
huge ``--harmonics`` never blames ``--samples``).
"""

from __future__ import annotations

import numpy as np

from .. import _validate as V
from .. import config
from ..kinematics import NormalSpring

__all__ = ["hb_bytes", "check_hb_sizes"]

#: float64 copies of the (unknowns x unknowns) Jacobian held at once: the
#: Jacobian and its scaled copy, their factorisation, the continuation's
#: bordered system, Hill's matrices (twice the size, complex)
_JACOBIAN_COPIES = 16
#: copies of the (samples x harmonics) synthesis and analysis matrices and
#: of the per-sample derivatives
_AFT_COPIES = 8
#: states whose every sample is kept by the AFT (hb._aft: small states)
_HISTORY_STATE = 16


def _unknown_dofs(system) -> int:
    """DOFs whose harmonics are unknowns: all of a small system; at least
    the contact DOFs (and DOF 0) of one condensed onto them."""
    n = system.ndof
    if n < config.HB_CONDENSE_MIN_DOFS:
        return n
    keep = {0, system.response_dof}
    for c in system.contacts:
        for sel in (c, c.normal) if isinstance(c.normal, NormalSpring) else (c,):
            if sel.direction is not None:
                keep.update(np.flatnonzero(np.asarray(sel.direction) != 0.0).tolist())
            else:
                keep.update(d for d in (sel.dof, sel.dof2) if d >= 0)
    return len(keep)


def hb_bytes(system, harmonics: int, samples: int) -> float:
    """Estimated bytes of a harmonic-balance solution of ``system`` with
    ``harmonics`` harmonics and ``samples`` AFT samples per period (a float:
    huge sizes give huge numbers, never an overflow)."""
    nh = 2.0 * float(harmonics) + 1.0
    ns = float(samples)
    nd = 2.0 * nh + 1.0
    ssz = float(max([c.law.state_size for c in system.contacts], default=1))
    nc = float(len(system.contacts))
    words = (_JACOBIAN_COPIES * (_unknown_dofs(system) * nh) ** 2 + _AFT_COPIES * ns * nd
             + 4.0 * ssz * nd + 4.0 * nc * ns + (ns * ssz * (nd + 1.0) if ssz <= _HISTORY_STATE else 0.0))
    return 8.0 * words


def _largest(nbytes, low: int) -> int:
    """The largest integer k >= ``low`` with ``nbytes(k)`` within the memory
    bound (``low`` when none is; ``nbytes`` increasing)."""
    budget = V.memory_budget()
    lo, hi = low, max(low, 1)
    while nbytes(hi) <= budget:
        lo, hi = hi, 2 * hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if nbytes(mid) <= budget else (lo, mid)
    return lo


def check_hb_sizes(system, harmonics, samples, *, given_samples: bool) -> None:
    """ValueError naming --harmonics or --samples (with the largest value that
    fits) when the harmonic balance of ``system`` would exceed the memory
    bound; ``"auto"`` values are the automatic choice, bounded by config and
    not checked here. ``--harmonics`` is estimated with the fewest samples it
    needs (2H + 2), so that its own size is what it is blamed for."""
    if isinstance(harmonics, int):
        top = _largest(lambda h: hb_bytes(system, h, 2 * h + 2), 1)
        V.memory_fits(f"--harmonics {harmonics}", hb_bytes(system, harmonics, 2 * harmonics + 2),
                      hint=f"--harmonics must be at most {top} here")
    if isinstance(samples, int) and given_samples:
        h = harmonics if isinstance(harmonics, int) else config.HB_HARMONICS
        top = _largest(lambda ns: hb_bytes(system, h, ns), 2 * h + 2)
        V.memory_fits(f"--samples {samples}", hb_bytes(system, h, samples),
                      hint=f"--samples must be at most {top} here (with {h} harmonics)")
