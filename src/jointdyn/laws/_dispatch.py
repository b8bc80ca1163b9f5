"""Several contact laws behind one set of kernels (mixed laws in one system).

Compiled loops (the RK4 runner, the harmonic-balance AFT, the law march)
bind one ``STEP`` (``STEP_JVP``, ``INIT``, ``INIT_JVP``) kernel with the law
contract's signatures (:mod:`jointdyn.laws._base`) and pass each contact its
own parameter row. :func:`law_dispatch` gives such a set of kernels for the
laws of a system's contacts:

* one kernel family (every contact's law has the same kernels, e.g.
  ``discrete`` with several ``n``): the laws' own kernels, bound directly, and
  parameter rows exactly as today (``law.params``, zero padded to a common
  width), so results and speed are those of a single-law system;
* several families (at most :data:`MAX_LAW_SLOTS`): dispatchers compiled
  from templates whose slots ``K0..K3`` are bound to the families' kernels
  (:func:`jointdyn._jit.specialize`, disk-cached per combination); each
  parameter row carries its slot number in its last column, which the
  dispatcher reads (the kernels read their own leading entries only, as
  with the zero padding of single-law systems).

Layout of :attr:`LawDispatch.P` (float64, (nc, width)): row c is
``laws[c].params`` followed by zeros; with several families ``width`` is
one more than the longest parameter vector and ``P[c, width - 1]`` is the
slot (0, 1, ...) of contact c's kernel family. States are (nc,
``state_size``) with each law's state in the leading entries.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._jit import jit, specialize
from ._base import SEPARATION

__all__ = ["MAX_LAW_SLOTS", "LawDispatch", "law_dispatch", "no_contact_step", "no_contact_step_jvp",
           "no_contact_init", "no_contact_init_jvp"]

#: most kernel families in one system (slots of the dispatchers)
MAX_LAW_SLOTS = 4


# --- kernels that exert no force -------------------------------------------------------
# bound for the unused slots of the dispatchers (no row carries their slot) and,
# re-exported by jointdyn.kinematics, in the compiled loops of systems without
# contacts (no contact to call them); they are not a contact law and are
# registered nowhere


@jit
def no_contact_step(params, s_old, s_new, x, N):  # pragma: no cover - never reached
    """Kernel that exerts no force (unused slots, systems without contacts)."""
    return 0.0, 0.0, SEPARATION


@jit
def no_contact_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):  # pragma: no cover - never reached
    """Forward-mode twin of :func:`no_contact_step` (no force, no derivative)."""
    for j in range(dT.shape[0]):
        dT[j] = 0.0
    return 0.0, 0.0, SEPARATION


@jit
def no_contact_init(params, x0, n0, s):  # pragma: no cover - never reached
    """Virgin state of :func:`no_contact_step` (zeros)."""
    for r in range(s.shape[0]):
        s[r] = 0.0


@jit
def no_contact_init_jvp(params, x0, dx0, n0, dn0, s, ds):  # pragma: no cover - never reached
    """:func:`no_contact_init` with derivatives (all zero)."""
    for r in range(s.shape[0]):
        s[r] = 0.0
        for j in range(ds.shape[1]):
            ds[r, j] = 0.0


# --- dispatch templates (slots K0..K3 bound by specialize) ------------------------------


@jit(inline="always")
def _slot(params):  # pragma: no cover - compiled
    """The kernel slot of a parameter row (its last entry)."""
    return int(params[params.shape[0] - 1])


def _step_template(params, s_old, s_new, x, N):  # pragma: no cover - compiled
    """``step`` of the law whose slot row ``params`` carries."""
    k = _slot(params)
    if k == 0:
        return K0(params, s_old, s_new, x, N)  # noqa: F821 - bound by specialize
    if k == 1:
        return K1(params, s_old, s_new, x, N)  # noqa: F821
    if k == 2:
        return K2(params, s_old, s_new, x, N)  # noqa: F821
    return K3(params, s_old, s_new, x, N)  # noqa: F821


def _step_jvp_template(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):  # pragma: no cover - compiled
    """``step_jvp`` of the law whose slot row ``params`` carries."""
    k = _slot(params)
    if k == 0:
        return K0(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT)  # noqa: F821
    if k == 1:
        return K1(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT)  # noqa: F821
    if k == 2:
        return K2(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT)  # noqa: F821
    return K3(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT)  # noqa: F821


def _init_template(params, x0, n0, s):  # pragma: no cover - compiled
    """``init`` of the law whose slot row ``params`` carries."""
    k = _slot(params)
    if k == 0:
        K0(params, x0, n0, s)  # noqa: F821
    elif k == 1:
        K1(params, x0, n0, s)  # noqa: F821
    elif k == 2:
        K2(params, x0, n0, s)  # noqa: F821
    else:
        K3(params, x0, n0, s)  # noqa: F821


def _init_jvp_template(params, x0, dx0, n0, dn0, s, ds):  # pragma: no cover - compiled
    """``init_jvp`` of the law whose slot row ``params`` carries."""
    k = _slot(params)
    if k == 0:
        K0(params, x0, dx0, n0, dn0, s, ds)  # noqa: F821
    elif k == 1:
        K1(params, x0, dx0, n0, dn0, s, ds)  # noqa: F821
    elif k == 2:
        K2(params, x0, dx0, n0, dn0, s, ds)  # noqa: F821
    else:
        K3(params, x0, dx0, n0, dn0, s, ds)  # noqa: F821


_TEMPLATES = (
    ("step", _step_template, no_contact_step),
    ("step_jvp", _step_jvp_template, no_contact_step_jvp),
    ("init", _init_template, no_contact_init),
    ("init_jvp", _init_jvp_template, no_contact_init_jvp),
)


@dataclass(frozen=True)
class LawDispatch:
    """Kernels and parameter rows serving the contacts of one system.

    Attributes
    ----------
    step, step_jvp, init, init_jvp : numba dispatchers
        Kernels with the law contract's signatures; the laws' own when there
        is one kernel family, else dispatchers reading the slot of each row.
    P : ndarray of float64, shape (nc, width)
        Parameter row of each contact (module docstring).
    state_size : int
        Longest state of the laws (rows of a state table).
    slots : tuple of int
        Kernel slot of each contact (all 0 with one family).
    families : int
        Number of distinct kernel families.
    """

    step: object
    step_jvp: object
    init: object
    init_jvp: object
    P: np.ndarray
    state_size: int
    slots: tuple
    families: int

    @property
    def mixed(self) -> bool:
        """True when the kernels dispatch (several kernel families)."""
        return self.families > 1


def _family(law) -> tuple:
    """(step, step_jvp, init, init_jvp) of ``law``; a law without derivative
    kernels (a plug-in written for the time integrator only) gets the
    never-called placeholders in their rows."""
    out = []
    for name, _, unused in _TEMPLATES:
        try:
            out.append(getattr(law, name))
        except NotImplementedError:
            if name in ("step", "init"):
                raise
            out.append(unused)
    return tuple(out)


def law_dispatch(laws) -> LawDispatch:
    """The :class:`LawDispatch` of a sequence of contact laws (one per contact).

    Parameters
    ----------
    laws : sequence of ContactLaw
        At least one law; at most :data:`MAX_LAW_SLOTS` distinct kernel families.

    Raises
    ------
    ValueError
        No law, or more kernel families than slots.
    """
    laws = tuple(laws)
    if not laws:
        raise ValueError("laws must hold at least one contact law")
    fams: list = []
    slots = []
    for law in laws:
        f = _family(law)
        if f not in fams:
            fams.append(f)
        slots.append(fams.index(f))
    if len(fams) > MAX_LAW_SLOTS:
        raise ValueError(f"contacts: at most {MAX_LAW_SLOTS} different contact-law kernels in one system, "
                         f"got {len(fams)}")
    width = max(law.params.size for law in laws) + (1 if len(fams) > 1 else 0)
    P = np.zeros((len(laws), width))
    for i, law in enumerate(laws):
        P[i, : law.params.size] = law.params
        if len(fams) > 1:
            P[i, width - 1] = float(slots[i])
    kernels = fams[0] if len(fams) == 1 else _dispatchers(tuple(fams))
    return LawDispatch(*kernels, P=P, state_size=max(law.state_size for law in laws), slots=tuple(slots),
                       families=len(fams))  # fmt: skip


def _dispatchers(fams: tuple) -> tuple:
    """(step, step_jvp, init, init_jvp) dispatchers over the kernel families ``fams``."""
    out = []
    for r, (_, template, unused) in enumerate(_TEMPLATES):
        bound = {f"K{k}": (fams[k][r] if k < len(fams) else unused) for k in range(MAX_LAW_SLOTS)}
        out.append(specialize(template, **bound))
    return tuple(out)
