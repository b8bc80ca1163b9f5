"""A discretisation value of harmonic balance: how many harmonics and samples, each fixed or automatic.

What a caller asks for (``harmonics`` and ``samples``, each an integer or
:data:`AUTO`) is made into a :class:`Discretisation` once, by
:meth:`Discretisation.of`, which validates both and names the one that is
wrong; a branch or a backbone at one discretisation is computed at a
:class:`Level` (H harmonics, Ns samples), which is validated where it is
made, too. The automatic choice (:mod:`jointdyn.hb.discretisation`, and the
backbones of :mod:`jointdyn.modes`) moves from level to level and never
re-checks them. :func:`check_memory` bounds the arrays a request sets by the
memory before anything is computed; the entry points of harmonic balance and
of EPMC call it, and the command line calls the same functions to refuse a
request before it writes anything.

This module sits below every other module of :mod:`jointdyn.hb` (the
problem validates its harmonics and samples through :meth:`Level.of`): it
imports no other module of :mod:`jointdyn.hb`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .. import _validate as V
from .. import config
from ..kinematics import NormalSpring
from .options import HBOptions, hb_options

__all__ = ["AUTO", "Level", "Discretisation", "hb_bytes", "check_memory"]

#: the value of ``harmonics`` or ``samples`` (and of ``--harmonics``, ``--samples``) asking for the
#: automatic choice
AUTO = "auto"


class Level(NamedTuple):
    """H harmonics (0..H are used) and Ns AFT samples per period (Ns >= 2H + 2) of one branch.

    A tuple, so that levels compare, hash and print as ``(H, Ns)``; make one
    with :meth:`of`, which validates it.
    """

    harmonics: int
    samples: int

    @classmethod
    def of(cls, harmonics, samples, names=("harmonics", "samples")) -> "Level":
        """The level with these values: ValueError naming ``names[0]`` or ``names[1]`` unless H >= 1 and
        Ns >= 2H + 2 (the samples resolve the highest harmonic of a product of two)."""
        H = V.positive_int(names[0], harmonics, 1)
        return cls(H, V.positive_int(names[1], samples, 2 * H + 2))


@dataclass(frozen=True)
class Discretisation:
    """The discretisation a caller asked for: the first :class:`Level` and which of its two values the
    automatic choice may raise (``"auto"``) rather than keep (a fixed integer)."""

    first: Level
    harmonics_auto: bool
    samples_auto: bool

    @classmethod
    def of(cls, harmonics=AUTO, samples=AUTO, *, names=("harmonics", "samples")) -> "Discretisation":
        """The discretisation of ``harmonics`` and ``samples`` (each an integer or :data:`AUTO`).

        Automatic harmonics start at ``config.HB_HARMONICS``; automatic
        samples at ``config.HB_SAMPLES``, or 2H + 2 where H asks for more.
        Fixed samples must be at least 2H + 2 of the first H. A ValueError
        names the value that is wrong with ``names`` (the command line
        passes its options' names), the same message from the Python API and
        the command line.
        """
        h = _count_or_auto(names[0], harmonics, 1)
        H = config.HB_HARMONICS if h == AUTO else h
        s = _count_or_auto(names[1], samples, 2 * H + 2)
        first = Level(H, max(config.HB_SAMPLES, 2 * H + 2) if s == AUTO else s)
        return cls(first=first, harmonics_auto=h == AUTO, samples_auto=s == AUTO)


def _count_or_auto(name: str, value, minimum: int):
    if isinstance(value, str) and value == AUTO:
        return AUTO
    try:
        return V.positive_int(name, value, minimum)
    except ValueError:
        raise ValueError(f"{name} must be an integer >= {minimum} or {AUTO!r}, got {V.short_repr(value)}") from None


#: float64 copies of the (unknowns x unknowns) Jacobian held at once: the
#: Jacobian and its scaled copy, their factorisation, the continuation's
#: bordered system, Hill's matrices (twice the size, complex)
_JACOBIAN_COPIES = 16
#: copies of the (samples x harmonics) synthesis and analysis matrices and
#: of the per-sample derivatives
_AFT_COPIES = 8
#: states whose every sample is kept by the AFT (hb._aft: small states)
_HISTORY_STATE = 16


def _unknown_dofs(system, min_dofs: int) -> int:
    """DOFs whose harmonics are unknowns: all of a system of fewer than ``min_dofs`` DOFs (the smallest
    the automatic choice condenses, ``HBOptions.condense_min_dofs``); at least the contact DOFs (and
    DOF 0) of one condensed onto them."""
    n = system.ndof
    if n < min_dofs:
        return n
    keep = {0, system.response_dof}
    for c in system.contacts:
        for sel in (c, c.normal) if isinstance(c.normal, NormalSpring) else (c,):
            if sel.direction is not None:
                keep.update(np.flatnonzero(np.asarray(sel.direction) != 0.0).tolist())
            else:
                keep.update(d for d in (sel.dof, sel.dof2) if d >= 0)
    return len(keep)


def hb_bytes(system, harmonics: int, samples: int, options: HBOptions | None = None) -> float:
    """Estimated bytes of a harmonic-balance solution of ``system`` with
    ``harmonics`` harmonics and ``samples`` AFT samples per period (a float:
    huge sizes give huge numbers, never an overflow; ``options``: the
    :class:`~jointdyn.hb.options.HBOptions` of the solution, None: the defaults)."""
    min_dofs = hb_options(options).condense_min_dofs
    nh = 2.0 * float(harmonics) + 1.0
    ns = float(samples)
    nd = 2.0 * nh + 1.0
    ssz = float(max([c.law.state_size for c in system.contacts], default=1))
    nc = float(len(system.contacts))
    words = (_JACOBIAN_COPIES * (_unknown_dofs(system, min_dofs) * nh) ** 2 + _AFT_COPIES * ns * nd
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


def check_memory(system, disc: Discretisation, names=("harmonics", "samples"),
                 options: HBOptions | None = None) -> None:
    """ValueError naming the fixed harmonics or samples of ``disc`` (with the largest value that fits)
    when the harmonic balance of ``system`` would exceed the memory bound
    (:func:`jointdyn._validate.memory_budget`); automatic values are bounded by
    ``HBOptions.auto_max_harmonics`` and ``auto_max_samples`` and not checked here (``options``:
    the :class:`~jointdyn.hb.options.HBOptions` of the solution, None: the defaults). Fixed harmonics
    are estimated with the fewest samples they need (2H + 2), so that their own
    size is what they are blamed for, never the default samples."""
    H, Ns = disc.first
    if not disc.harmonics_auto:
        top = _largest(lambda h: hb_bytes(system, h, 2 * h + 2, options), 1)
        V.memory_fits(f"{names[0]} {H}", hb_bytes(system, H, 2 * H + 2, options),
                      hint=f"{names[0]} must be at most {top} here")
    if not disc.samples_auto:
        top = _largest(lambda ns: hb_bytes(system, H, ns, options), 2 * H + 2)
        V.memory_fits(f"{names[1]} {Ns}", hb_bytes(system, H, Ns, options),
                      hint=f"{names[1]} must be at most {top} here (with {H} harmonics)")
