"""The contact-law contract shared by every law, and the law registry.

Everything a solver (driver, time integrator, harmonic balance) relies on is
stated here; a law that honours it works everywhere in jointdyn.

Kernels (OpenSees-style trial step from a committed state)
-----------------------------------------------------------
Every contact law provides four compiled kernels (compiled with
:func:`jointdyn._jit.jit`, so that the loops that bind them are disk-cached)::

    T, kT, code = step(params, s_old, s_new, x, N)
    T, kT, code = step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT)
    init(params, x0, n0, s)
    init_jvp(params, x0, dx0, n0, dn0, s, ds)

``params``  float64[:]   the law's parameters (``law.params``), possibly followed by
                         more entries (padding to a common width, the slot of
                         a mixed-law dispatch, laws/_dispatch.py): a kernel
                         reads its own leading entries only
``s_old``   float64[:]   committed state, length ``law.state_size``
``s_new``   float64[:]   trial state (same length)
``x``       float        tangential relative displacement, m
``N``       float        normal load, N (compressive positive; N <= 0 is open)
``T``       float        tangential contact force, N
``kT``      float        tangent, N/m
``code``    int          motion state: STICK_SLIP, MACROSLIP or SEPARATION

What ``step`` guarantees (and ``step_jvp`` identically for its primal outputs,
bit for bit):

1. It never writes ``s_old`` and writes ``s_new`` in full (every entry a
   later step or ``check_state`` looks at), so committing is the caller
   swapping the two buffers, and a trial can be repeated from the same
   ``s_old``. It allocates nothing: drivers, integrators and harmonic
   balance call it in their innermost loops.
2. ``N <= 0``: T = 0, kT = 0 and code SEPARATION (and only then).
3. ``kT = dT/dx`` at fixed ``N`` and fixed committed state, with
   ``0 <= kT <= kt``; MACROSLIP (every slider slipping) has ``kT = 0``.
4. ``|T| <= law.max_force(N)``: for the friction laws of this package
   ``(N / n_ref) fy`` with ``fy = mu n_ref``, up to rounding.
5. The state carries the whole history: marching a history in two pieces,
   the second from the state the first returned, equals one march.
6. ``law.passive``: no energy is created over any closed displacement cycle
   at constant N from any committed state (Ilyushin's postulate; the
   paper's last-reversal rule is the exception). From the virgin state every
   law here is passive.

``step_jvp`` also propagates forward-mode derivatives along ``ndir``
directions at once: ``ds_old``/``ds_new`` are ``(state_size, ndir)``, ``dx``,
``dN`` and the output ``dT`` are ``(ndir,)``. The derivative of the state
carries the history, so the chain rule through a whole march is exact (away
from the measure-zero instants of motion-state transitions).

Virgin state
------------
``init`` writes into ``s`` (in full) the virgin committed state at
displacement ``x0`` (m) and normal load ``n0`` (N): the law at rest there,
so that a step to ``(x0, n0)`` from it returns T = 0 with code STICK_SLIP
(``n0 > 0``) or SEPARATION (``n0 <= 0``). ``law.initial_state`` is that
kernel called from Python, and compiled loops that restart a law call it
directly. ``init_jvp`` does the same and writes the *exact* derivative of
that state along ``ndir`` directions (``dx0``, ``dn0`` are ``(ndir,)``,
``ds`` is ``(state_size, ndir)``): solvers whose restart point depends on
their unknowns (harmonic balance restarts every contact at the mean
displacement of each evaluation) take the derivative from here, never by
differencing the state, and assume nothing about how the state depends on
``x0`` and ``n0``.

Scales
------
Solvers that make unknowns dimensionless use ``law.fy`` (force, N, the
macroslip force at ``n_ref``), ``law.kt`` (stiffness, N/m) and
``law.displacement_scale = fy / kt`` (m); ``law.x_slip`` is the law's own
displacement to macroslip on the virgin curve at ``N = n_ref`` (m), the
natural amplitude unit of its loops. Both displacement scales are 0 when
``mu = 0`` (no friction): solvers then fall back to a scale of their own.
The constructors guarantee that all of them, and ``kt / fy``, are finite.

States given by users
---------------------
``law.check_state(state)`` validates a state before any compiled call
(shape ``(state_size,)``, finite live part, and what the law's kernels need
to neither crash nor return NaN) and raises ValueError naming ``state``.

Adding a law
------------
A new law is one module in this package: its kernels, a thin frozen
dataclass deriving from :class:`ContactLaw` (law-specific parameters declared
with :func:`law_param`) and a call of :func:`register`. The package imports
every module of ``jointdyn.laws`` whose name does not start with ``_``, so
nothing else needs an edit: the law is then available by name to
:func:`make_law`, ``jointdyn loop``, ``jointdyn frc`` (``--model NAME
--law-param KEY=VALUE``), :func:`jointdyn.sweeps.frc_sweep` and
:meth:`jointdyn.System.paper_damper` (``law_params``), and the law tests
iterate it.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import _validate as V
from .. import config

__all__ = [
    "STICK_SLIP",
    "MACROSLIP",
    "SEPARATION",
    "STATE_NAMES",
    "ContactLaw",
    "LawParameter",
    "law_param",
    "register",
    "make_law",
    "law_names",
    "law_parameters",
    "law_summary",
    "law_label",
    "canonical_law_params",
]

#: copies of a contact law's state a solver holds at once (trial and committed states, their
#: forward-mode derivatives): a law whose state times this exceeds the bound is refused
LAW_STATE_COPIES = 16

#: part of the interface sticks while part slips (microslip); for a single
#: Jenkins element: stuck
STICK_SLIP = 0
#: every slider slips, |T| = alpha fy
MACROSLIP = 1
#: open contact, N <= 0, T = 0
SEPARATION = 2
STATE_NAMES = ("stick-slip", "macroslip", "separation")

#: kernels multiply the scales (fy, kt / fy, fy / kt, 1 / n_ref) by small
#: factors (2 in the backbone, sums of element limits): each must stay below
#: the largest double divided by this headroom
_SCALE_HEADROOM = 16.0
_HUGE = sys.float_info.max / _SCALE_HEADROOM
_PARAM_KEY = "jointdyn_law_param"


@dataclass(frozen=True)
class LawParameter:
    """A law-specific parameter, as front ends list and validate it.

    Attributes
    ----------
    name : str
        Keyword of :func:`make_law` (and ``--law-param NAME=VALUE``).
    default : int, float or str
        Value when not given.
    units : str
        Physical units ("-" for a number without units).
    help : str
        One line saying what it is.
    kind : {"int", "float", "choice"}
        Type a given value is converted to (strings from a command line
        included).
    low, high : float
        Allowed range of an int or float (closed bounds; +-inf when open-ended).
    choices : tuple of str
        Allowed values of a choice.
    """

    name: str
    default: object
    units: str
    help: str
    kind: str
    low: float = -math.inf
    high: float = math.inf
    choices: tuple = ()

    def allowed(self) -> str:
        """The allowed values, as an error message states them."""
        if self.kind == "choice":
            return "one of " + ", ".join(map(str, self.choices))
        what = "an integer" if self.kind == "int" else "a number"
        lb = "(" if self.low == -math.inf else "["
        rb = ")" if self.high == math.inf else "]"
        return f"{what} in {lb}{self.low:g}, {self.high:g}{rb}"

    def check(self, value):
        """``value`` converted to the parameter's kind; ValueError naming the
        parameter and its allowed values otherwise."""
        if self.kind == "choice":
            if value not in self.choices:
                raise ValueError(f"{self.name} must be {self.allowed()}; got {value!r}")
            return value
        shown = V.short_repr(value)
        bad = ValueError(f"{self.name} must be {self.allowed()}, got {shown}")
        if isinstance(value, bool):
            raise bad
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            raise bad from None
        if not (math.isfinite(v) and self.low <= v <= self.high):
            raise bad
        if self.kind == "int":
            if v != int(v):
                raise bad
            return int(v)
        return v


def law_param(default, *, help: str, units: str = "-", low=None, high=None, choices=None, kind=None):
    """Dataclass field declaring a law-specific parameter.

    Use it for every field of a :class:`ContactLaw` subclass beyond kt, mu
    and n_ref; the base class validates the value against the declaration
    and the registry lists it (:func:`law_parameters`).

    Parameters
    ----------
    default : int, float or str
        Default value; its type gives the kind unless ``kind`` or
        ``choices`` is given.
    help : str
        One line saying what the parameter is.
    units : str
        Physical units ("-" for none).
    low, high : float, optional
        Closed bounds of the allowed range (default unbounded).
    choices : sequence of str, optional
        Allowed values (a choice parameter).
    kind : {"int", "float", "choice"}, optional
        Overrides the kind inferred from ``default``.
    """
    if kind is None:
        kind = "choice" if choices is not None else ("int" if isinstance(default, int) else "float")
    spec = dict(
        default=default,
        units=units,
        help=help,
        kind=kind,
        low=-math.inf if low is None else float(low),
        high=math.inf if high is None else float(high),
        choices=tuple(choices or ()),
    )
    return dataclasses.field(default=default, metadata={_PARAM_KEY: spec})


def _declared_parameters(cls) -> tuple:
    """The :class:`LawParameter` of every field of ``cls`` declared with :func:`law_param`."""
    return tuple(
        LawParameter(name=f.name, **f.metadata[_PARAM_KEY])
        for f in dataclasses.fields(cls)
        if _PARAM_KEY in f.metadata
    )


@dataclass(frozen=True)
class ContactLaw:
    """Base of all contact laws: validated parameters, no history.

    Subclasses provide the kernels and ``params``, ``state_size`` and
    ``x_slip`` (see the module docstring); law-specific fields are declared
    with :func:`law_param` and validated here.

    Attributes
    ----------
    kt : float
        Total tangential stiffness, N/m (> 0).
    mu : float
        Friction coefficient (>= 0).
    n_ref : float
        Reference normal load N_ref, N (> 0). ``alpha = N / n_ref``.
    """

    kt: float
    mu: float
    n_ref: float

    name: ClassVar[str] = "base"
    #: True when the force has no jump and no kink at the onset of slip (a distribution of
    #: slip thresholds, as the exact Iwan law): harmonic balance then starts each Newton
    #: correction of its continuation from an extrapolation of the branch
    #: (``continuation.START_EXTRAPOLATION``); False (the safe default of a new law) starts it
    #: from the tangent prediction
    smooth_force: ClassVar[bool] = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "kt", V.positive("kt", self.kt))
        object.__setattr__(self, "mu", V.nonnegative("mu", self.mu))
        object.__setattr__(self, "n_ref", V.positive("n_ref", self.n_ref))
        for p in _declared_parameters(type(self)):
            object.__setattr__(self, p.name, p.check(getattr(self, p.name)))
        self._check_state_size()
        self._check_scales()

    def _check_state_size(self) -> None:
        """The state, in the copies the solvers hold (``LAW_STATE_COPIES``),
        fits the memory bound: ValueError naming the integer law parameter that
        sets its size (with the largest value that fits) otherwise."""
        nbytes = 8.0 * self.state_size * LAW_STATE_COPIES
        budget = V.memory_budget()
        if nbytes <= budget:
            return
        for p in _declared_parameters(type(self)):
            if p.kind == "int":
                v = getattr(self, p.name)
                hi = max(int(p.low), int(v * budget // nbytes))
                V.memory_fits(f"{p.name} = {v}", nbytes, hint=f"{p.name} must be at most {hi} "
                              f"(a state of {self.state_size} numbers, {LAW_STATE_COPIES} copies)")
        V.memory_fits(f"the state of {type(self).__name__} ({self.state_size} numbers)", nbytes)

    def _check_scales(self) -> None:
        """The derived scales are finite (with headroom): ValueError naming
        the parameter to change and its allowed range otherwise."""
        kt, mu, n_ref = self.kt, self.mu, self.n_ref
        if not 1.0 / n_ref <= _HUGE:
            lo = 1.0 / _HUGE
            raise ValueError(f"n_ref must be in [{lo:.6g}, inf) so that 1 / n_ref is finite, got {n_ref!r}")
        hi = _HUGE / n_ref
        if not mu <= hi:
            raise ValueError(
                f"mu must be in [0, {hi:.6g}] with n_ref = {n_ref:g} N so that fy = mu n_ref is finite, got {mu!r}"
            )
        fy = mu * n_ref
        if fy > 0.0 and not kt / fy <= _HUGE:
            lo = kt / (_HUGE * n_ref)
            raise ValueError(
                f"mu must be 0 or in [{lo:.6g}, {hi:.6g}] with kt = {kt:g} N/m and n_ref = {n_ref:g} N so that "
                f"kt / fy is finite, got {mu!r}"
            )
        if not fy / kt <= _HUGE:
            lo = fy / _HUGE
            raise ValueError(f"kt must be in [{lo:.6g}, inf) with fy = {fy:g} N so that fy / kt is finite, got {kt!r}")
        if not math.isfinite(self.x_slip):
            raise ValueError(f"kt must be larger: x_slip of {type(self).__name__} overflows with kt = {kt!r} N/m")

    # --- what subclasses provide ------------------------------------------
    #: the law's compiled kernels ``(step, step_jvp, init, init_jvp)`` (a law
    #: without derivative kernels gives two: ``(step, None, init, None)`` or
    #: leaves them out); a law may instead override the four properties
    kernels: ClassVar[tuple] = ()

    def _kernel(self, i: int, what: str):
        k = self.kernels[i] if i < len(self.kernels) else None
        if k is None:
            raise NotImplementedError(f"{type(self).__name__} has no {what} kernel")
        return k

    @property
    def step(self):
        """The compiled trial-step kernel (see module docstring)."""
        return self._kernel(0, "step")

    @property
    def step_jvp(self):
        """The compiled forward-mode kernel (see module docstring)."""
        return self._kernel(1, "step_jvp")

    @property
    def init(self):
        """The compiled virgin-state kernel ``init(params, x0, n0, s)`` (see module docstring)."""
        return self._kernel(2, "init")

    @property
    def init_jvp(self):
        """The compiled kernel ``init_jvp(params, x0, dx0, n0, dn0, s, ds)`` (see module docstring)."""
        return self._kernel(3, "init_jvp")

    @property
    def params(self) -> np.ndarray:
        """float64 parameter vector passed to the kernels."""
        raise NotImplementedError

    @property
    def state_size(self) -> int:
        """Length of the state vector."""
        raise NotImplementedError

    @property
    def x_slip(self) -> float:
        """Displacement from the virgin state to macroslip at N = n_ref, m."""
        raise NotImplementedError

    def _state_error(self, s: np.ndarray) -> str | None:
        """Why a state of the right shape is not admissible (None if it is).

        The default requires every entry finite; laws whose state has rows
        that the kernels never read (an unused stack) or integer fields
        override it.
        """
        if not np.all(np.isfinite(s)):
            i = int(np.flatnonzero(~np.isfinite(s))[0])
            return f"entry {i} is {float(s[i])!r} (every entry must be finite)"
        return None

    # --- shared -------------------------------------------------------------
    def check_state(self, state) -> np.ndarray:
        """A user-supplied committed state, validated for the kernels.

        Parameters
        ----------
        state : array_like
            Committed state, shape ``(state_size,)``.

        Returns
        -------
        ndarray
            float64 copy of ``state``.

        Raises
        ------
        ValueError
            Naming ``state``: wrong type or shape, non-finite live entries,
            or values the kernels cannot start from (law-specific).
        """
        try:
            s = np.array(state, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"state must be an array of real numbers, got {type(state).__name__}") from None
        if s.ndim != 1 or s.shape[0] != self.state_size:
            raise ValueError(f"state must have shape ({self.state_size},) (law.state_size), got {s.shape}")
        err = self._state_error(s)
        if err is not None:
            raise ValueError(f"state is not a valid {type(self).__name__} state: {err}")
        return s

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
        """Macroslip force at the reference load, mu * n_ref (N): the force scale."""
        return self.mu * self.n_ref

    @property
    def displacement_scale(self) -> float:
        """fy / kt (m): the displacement scale solvers use for their unknowns."""
        return self.fy / self.kt

    def max_force(self, N):
        """Bound on |T| at normal load ``N`` (N): ``max(N, 0) / n_ref * fy``.

        Laws whose slip limit is not ``mu N`` override it.
        """
        return np.maximum(N, 0.0) / self.n_ref * self.fy

    @property
    def passive(self) -> bool:
        """True when the law creates no energy over any closed displacement
        cycle at constant N from any committed state (contract item 6)."""
        return True

    def law_params(self) -> dict:
        """Values of the law-specific parameters (fields declared with :func:`law_param`)."""
        return {p.name: getattr(self, p.name) for p in _declared_parameters(type(self))}


# --- registry -----------------------------------------------------------------


@dataclass(frozen=True)
class _Entry:
    law: type
    fixed: tuple
    summary: str
    label: str


_REGISTRY: dict[str, _Entry] = {}


def register(name: str, law: type, *, fixed: dict | None = None, summary: str | None = None,
             label: str | None = None) -> None:
    """Make a law constructible by name (:func:`make_law`, CLI ``--model``).

    Parameters
    ----------
    name : str
        Registered name (e.g. ``"iwan"``).
    law : type
        The :class:`ContactLaw` subclass.
    fixed : dict, optional
        Law parameters this name fixes (e.g. ``{"memory": "last"}`` for
        ``iwan-paper``); they are not listed nor accepted by :func:`make_law`.
    summary : str, optional
        One-line description (default: the first line of the class docstring).
    label : str, optional
        Short name in figure titles and legends (e.g. ``"exact Iwan model"``;
        default: the registered name); see :func:`law_label`.
    """
    if not (isinstance(law, type) and issubclass(law, ContactLaw)):
        raise ValueError(f"law must be a ContactLaw subclass, got {law!r}")
    fixed = dict(fixed or {})
    declared = {p.name for p in _declared_parameters(law)}
    for key in fixed:
        if key not in declared:
            raise ValueError(f"fixed parameter {key!r} is not a law parameter of {law.__name__}")
    if summary is None:
        summary = (law.__doc__ or law.__name__).strip().splitlines()[0].rstrip(".")
    old = _REGISTRY.get(name)
    where = f"{law.__module__}.{law.__qualname__}"
    if old is not None and f"{old.law.__module__}.{old.law.__qualname__}" != where:
        # a module imported again (reload) registers the same class again; a
        # different class under a taken name is an error
        raise ValueError(f"law name {name!r} is already registered by {old.law.__module__}.{old.law.__qualname__}")
    _REGISTRY[name] = _Entry(law=law, fixed=tuple(sorted(fixed.items())), summary=summary,
                             label=name if label is None else str(label))


def law_names() -> list[str]:
    """Names accepted by :func:`make_law`, sorted."""
    return sorted(_REGISTRY)


def _entry(name: str) -> _Entry:
    V.choice("model", name, law_names())
    return _REGISTRY[name]


def law_summary(name: str) -> str:
    """One-line description of a registered law."""
    return _entry(name).summary


def law_label(name: str) -> str:
    """Short name of a registered law in figure titles and legends (its ``label``, or its name)."""
    return _entry(name).label


def law_parameters(name: str) -> tuple:
    """The law-specific parameters of a registered law (tuple of :class:`LawParameter`)."""
    e = _entry(name)
    fixed = dict(e.fixed)
    return tuple(p for p in _declared_parameters(e.law) if p.name not in fixed)


def _checked_params(name: str, law_params: dict) -> dict:
    """Given law parameters converted and validated; ValueError naming an unknown one."""
    allowed = {p.name: p for p in law_parameters(name)}
    out = {}
    for key, value in law_params.items():
        if key not in allowed:
            listed = ", ".join(allowed) if allowed else "none"
            raise ValueError(f"{key} is not a parameter of model {name} (its law parameters: {listed})")
        out[key] = allowed[key].check(value)
    return out


def canonical_law_params(name: str, law_params: dict | None = None) -> tuple:
    """Every law-specific parameter of ``name`` with its value, as a sorted tuple.

    Given values are validated and converted; the others take their
    defaults, so that equal laws have equal tuples (used in resume keys).
    """
    given = _checked_params(name, dict(law_params or {}))
    return tuple(sorted((p.name, given.get(p.name, p.default)) for p in law_parameters(name)))


def make_law(name: str, *, kt: float, mu: float, n_ref: float, **law_params) -> ContactLaw:
    """Construct a registered contact law by name.

    Parameters
    ----------
    name : str
        One of :func:`law_names`: ``iwan`` (the exact Iwan model with
        varying normal load, the default of every front end,
        ``config.MODEL``), ``iwan-closed`` (the closed form with full Masing
        memory), ``iwan-paper`` (the closed form with the paper's
        last-reversal rule), ``discrete`` (n Jenkins elements), ``jenkins``,
        and any law module added to the package.
    kt : float
        Total tangential stiffness, N/m (> 0).
    mu : float
        Friction coefficient (>= 0).
    n_ref : float
        Reference normal load N_ref, N (> 0); fy = mu * n_ref.
    **law_params
        Law-specific parameters (:func:`law_parameters`), e.g. ``capacity``
        of ``iwan`` or ``n`` of ``discrete``; strings are converted
        (command lines).

    Raises
    ------
    ValueError
        Unknown name, a parameter the law does not have (the message lists
        the allowed ones), or a value out of range.
    """
    e = _entry(name)
    given = _checked_params(name, law_params)
    return e.law(kt=kt, mu=mu, n_ref=n_ref, **dict(e.fixed), **given)
