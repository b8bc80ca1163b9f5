"""The contact-law contract shared by every law, and the law registry.

Kernel contract (OpenSees-style trial step from a committed state)
-------------------------------------------------------------------
Every contact law provides four compiled kernels::

    T, kT, code = step(params, s_old, s_new, x, N)
    T, kT, code = step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT)
    init(params, x0, n0, s)
    init_jvp(params, x0, dx0, n0, dn0, s, ds)

``init`` writes into ``s`` (in full) the virgin committed state at
displacement ``x0`` (m) and normal load ``n0`` (N); ``law.initial_state`` is
that kernel called from Python, and compiled loops that restart a law call it
directly. ``init_jvp`` does the same and writes the exact derivative of that
state along ``ndir`` directions: ``dx0``, ``dn0`` are ``(ndir,)`` and ``ds``
is ``(state_size, ndir)``. Solvers that restart a law from a state that
depends on their unknowns (harmonic balance restarts every contact at the
mean displacement of each evaluation) take the derivative from here, never
by differencing the state.

``params``  float64[:]   the law's parameters (from ``law.params``)
``s_old``   float64[:]   committed state; **never written**
``s_new``   float64[:]   trial state, written in full (same length)
``x``       float        tangential relative displacement, m
``N``       float        normal load, N (compressive positive; N <= 0 is open)
``T``       float        tangential contact force, N
``kT``      float        tangent dT/dx at fixed N, N/m
``code``    int          motion state: STICK_SLIP, MACROSLIP or SEPARATION

``step_jvp`` additionally propagates forward-mode derivatives along ``ndir``
directions at once: ``ds_old``/``ds_new`` are ``(state_size, ndir)``,
``dx``, ``dN`` and the output ``dT`` are ``(ndir,)``. The derivative of the
state carries the history, so the chain rule through a whole time march is
exact (away from the measure-zero instants of state transitions).

Committing is the caller's business: it swaps ``s_old`` and ``s_new``.
The kernels allocate nothing, so drivers, time integrators and harmonic
balance call them in their innermost loops.

A new law is one module with its three kernels and one thin frozen dataclass
deriving from :class:`ContactLaw`, which registers itself under a name with
:func:`register`; nothing else in the package needs an edit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, ClassVar

import numpy as np

from .. import _validate as V

__all__ = [
    "STICK_SLIP",
    "MACROSLIP",
    "SEPARATION",
    "STATE_NAMES",
    "ContactLaw",
    "register",
    "make_law",
    "law_names",
]

#: part of the interface sticks while part slips (microslip); for a single
#: Jenkins element: stuck
STICK_SLIP = 0
#: every slider slips, |T| = alpha fy
MACROSLIP = 1
#: open contact, N <= 0, T = 0
SEPARATION = 2
STATE_NAMES = ("stick-slip", "macroslip", "separation")

_REGISTRY: dict[str, Callable[..., "ContactLaw"]] = {}


def register(name: str, factory: Callable[..., "ContactLaw"]) -> None:
    """Make a law constructible by name (CLI ``--model``, :func:`make_law`).

    ``factory(kt=, mu=, n_ref=, **options)`` receives every option the user
    gave and takes what it needs (e.g. ``n`` for the discrete model).
    """
    _REGISTRY[name] = factory


def law_names() -> list[str]:
    """Names accepted by :func:`make_law`."""
    return sorted(_REGISTRY)


def make_law(name: str, *, kt: float, mu: float, n_ref: float, **options) -> "ContactLaw":
    """Construct a registered contact law by name.

    Parameters
    ----------
    name : str
        One of :func:`law_names` (``iwan``, ``iwan-paper``, ``discrete``,
        ``jenkins``).
    kt : float
        Total tangential stiffness, N/m (> 0).
    mu : float
        Friction coefficient (>= 0).
    n_ref : float
        Reference normal load N_ref, N (> 0); fy = mu * n_ref.
    **options
        Law-specific options, e.g. ``n`` (number of Jenkins elements).
    """
    V.choice("model", name, law_names())
    return _REGISTRY[name](kt=kt, mu=mu, n_ref=n_ref, **options)


@dataclass(frozen=True)
class ContactLaw:
    """Base of all contact laws: validated parameters, no history.

    Attributes
    ----------
    kt : float
        Total tangential stiffness, N/m.
    mu : float
        Friction coefficient.
    n_ref : float
        Reference normal load N_ref, N. ``alpha = N / n_ref``.
    """

    kt: float
    mu: float
    n_ref: float

    name: ClassVar[str] = "base"

    def __post_init__(self) -> None:
        object.__setattr__(self, "kt", V.positive("kt", self.kt))
        object.__setattr__(self, "mu", V.nonnegative("mu", self.mu))
        object.__setattr__(self, "n_ref", V.positive("n_ref", self.n_ref))

    # --- what subclasses provide ------------------------------------------
    @property
    def step(self):
        """The compiled trial-step kernel (see module docstring)."""
        raise NotImplementedError

    @property
    def step_jvp(self):
        """The compiled forward-mode kernel (see module docstring)."""
        raise NotImplementedError

    @property
    def params(self) -> np.ndarray:
        """float64 parameter vector passed to the kernels."""
        raise NotImplementedError

    @property
    def state_size(self) -> int:
        """Length of the state vector."""
        raise NotImplementedError

    @property
    def init(self):
        """The compiled virgin-state kernel ``init(params, x0, n0, s)`` (see module docstring)."""
        raise NotImplementedError

    @property
    def init_jvp(self):
        """The compiled kernel ``init_jvp(params, x0, dx0, n0, dn0, s, ds)`` (see module docstring)."""
        raise NotImplementedError

    # --- shared -------------------------------------------------------------
    def initial_state(self, x0: float = 0.0, n0: float | None = None) -> np.ndarray:
        """Virgin committed state at displacement ``x0`` (m) and load ``n0`` (N).

        ``n0`` defaults to ``n_ref`` (alpha = 1). Computed by the law's
        ``init`` kernel, the same code compiled loops call.
        """
        s = np.empty(self.state_size)
        self.init(self.params, float(x0), float(self.n_ref if n0 is None else n0), s)
        return s

    @property
    def fy(self) -> float:
        """Macroslip force at the reference load, mu * n_ref (N)."""
        return self.mu * self.n_ref

    @property
    def x_slip(self) -> float:
        """Displacement 2 fy / kt at which the virgin curve reaches macroslip (m)."""
        return 2.0 * self.fy / self.kt if self.kt > 0 else math.inf
