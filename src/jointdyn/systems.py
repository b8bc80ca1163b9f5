"""What the system is: mass, damping and stiffness, contacts, harmonic loads.

MODEL.md section 6::

    M x'' + C x' + K x = f sin(w t) - sum_c B_c T_c(u_c, N_c(t)),
    u_c = x[dof] - x[dof2] (or x[dof] against ground),
    N_c(t) = n0 + n1 sin(w t + delta).

The excitation frequency w is not part of the system: solvers take it (or
gamma = w / w0) as an argument, so one System serves a whole sweep. The
contact selection and the normal loads are packed for the solvers by
:func:`jointdyn.kinematics.contact_kinematics`, their one home.
All contacts of one system use the same contact-law class (one compiled
kernel); their parameters may differ.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from . import _validate as V
from . import config
from .kinematics import harmonic_load_samples
from .laws import ContactLaw, make_law

__all__ = ["Contact", "System", "PAPER"]

#: the paper's section-3 damper (MODEL.md section 6)
PAPER = dict(m=10.0, k=3.9e5, kt=3.0e5, kn=3.0e5, mu=0.5, n0=100.0)


@dataclass(frozen=True)
class Contact:
    """One frictional contact.

    Parameters
    ----------
    law : ContactLaw
        Tangential law; its ``n_ref`` is the reference load for alpha = N / n_ref.
    dof : int
        DOF whose displacement is the tangential slip (index into x).
    dof2 : int
        Second DOF (relative slip x[dof] - x[dof2]); -1 means ground.
    n0 : float
        Static normal load N0, N (> 0).
    n1 : float
        Amplitude N1 of the normal-load oscillation, N (>= 0); eta = n1 / n0.
    delta : float
        Phase of the normal load relative to the forcing, rad.
    """

    law: ContactLaw
    dof: int = 0
    dof2: int = -1
    n0: float = 100.0
    n1: float = 0.0
    delta: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.law, ContactLaw):
            raise ValueError(f"law must be a ContactLaw, got {type(self.law).__name__}")
        object.__setattr__(self, "dof", V.positive_int("dof", self.dof, 0))
        if self.dof2 != -1:
            object.__setattr__(self, "dof2", V.positive_int("dof2", self.dof2, 0))
        object.__setattr__(self, "n0", V.positive("n0", self.n0))
        object.__setattr__(self, "n1", V.nonnegative("n1", self.n1))
        object.__setattr__(self, "delta", V.finite("delta", self.delta))

    @property
    def eta(self) -> float:
        """N1 / N0."""
        return self.n1 / self.n0

    def normal_load(self, w: float, t):
        """N(t) = n0 + n1 sin(w t + delta), N (:func:`jointdyn.kinematics.harmonic_load`)."""
        return harmonic_load_samples(self.n0, self.n1, self.delta, w * np.asarray(t, dtype=float))


@dataclass(frozen=True)
class System:
    """Linear structure with frictional contacts and harmonic forcing.

    Parameters
    ----------
    M, C, K : array_like
        Mass (kg), viscous damping (N s/m) and stiffness (N/m) matrices, n x n.
    contacts : tuple of Contact
        Contacts (all with the same law class).
    force : array_like
        Forcing amplitudes f (N) per DOF: F(t) = f sin(w t).
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    contacts: tuple = field(default_factory=tuple)
    force: np.ndarray = None

    def __post_init__(self) -> None:
        M = V.finite_array("M", np.atleast_2d(self.M), 2)
        n = M.shape[0]
        C = V.finite_array("C", np.atleast_2d(self.C), 2)
        K = V.finite_array("K", np.atleast_2d(self.K), 2)
        for name, A in (("M", M), ("C", C), ("K", K)):
            if A.shape != (n, n):
                raise ValueError(f"{name} must be {n} x {n}, got shape {A.shape}")
        if np.any(np.linalg.eigvalsh(0.5 * (M + M.T)) <= 0):
            raise ValueError("M must be symmetric positive definite (eigenvalues in (0, inf))")
        f = np.zeros(n) if self.force is None else V.finite_array("force", np.atleast_1d(self.force))
        if f.shape != (n,):
            raise ValueError(f"force must have length {n}, got {f.shape[0]}")
        contacts = tuple(self.contacts)
        for c in contacts:
            if not isinstance(c, Contact):
                raise ValueError("contacts must be Contact instances")
            for d in (c.dof, c.dof2):
                if d >= n:
                    raise ValueError(f"contact dof must be in [0, {n - 1}] (or -1 for ground), got {d}")
        if len({type(c.law) for c in contacts}) > 1:
            raise ValueError("all contacts of one System must use the same contact-law class")
        object.__setattr__(self, "M", M)
        object.__setattr__(self, "C", C)
        object.__setattr__(self, "K", K)
        object.__setattr__(self, "force", f)
        object.__setattr__(self, "contacts", contacts)

    @property
    def ndof(self) -> int:
        return self.M.shape[0]

    @functools.cached_property
    def w0(self) -> float:
        """Lowest natural angular frequency of (M, K) without contacts, rad/s.

        For the single-DOF damper w0 = sqrt(k/m), the paper's reference for gamma.
        """
        from scipy.linalg import eigh

        lam = eigh(self.K, self.M, eigvals_only=True)
        return math.sqrt(max(lam[0], 0.0))

    @classmethod
    def sdof(
        cls,
        *,
        m: float,
        k: float,
        law: ContactLaw | None = None,
        f1: float = 0.0,
        c: float | None = None,
        zeta: float | None = None,
        n0: float | None = None,
        eta: float = 0.0,
        delta: float = 0.0,
    ) -> "System":
        """Single-DOF oscillator with one contact between mass and ground.

        Parameters
        ----------
        m : float
            Mass, kg (> 0).
        k : float
            Stiffness, N/m (> 0).
        law : ContactLaw, optional
            Contact law (none: linear oscillator).
        f1 : float
            Forcing amplitude F1, N.
        c, zeta : float, optional
            Viscous damping (N s/m) or ratio c / (2 sqrt(k m)); not both.
        n0 : float, optional
            Static normal load, N; default ``law.n_ref``.
        eta : float
            N1 / N0 (>= 0).
        delta : float
            Normal-load phase, rad.
        """
        m = V.positive("m", m)
        k = V.positive("k", k)
        if c is not None and zeta is not None:
            raise ValueError("give either c or zeta, not both")
        if zeta is not None:
            c = 2.0 * V.nonnegative("zeta", zeta) * math.sqrt(k * m)
        c = 0.0 if c is None else V.nonnegative("c", c)
        contacts = ()
        if law is not None:
            n0 = law.n_ref if n0 is None else n0
            eta = V.nonnegative("eta", eta)
            contacts = (Contact(law=law, dof=0, n0=n0, n1=eta * float(n0), delta=delta),)
        return cls(M=[[m]], C=[[c]], K=[[k]], contacts=contacts, force=[V.finite("f1", f1)])

    @classmethod
    def paper_damper(
        cls,
        *,
        eta: float = 0.5,
        beta: float = 1.0,
        delta: float = 0.0,
        model: str = config.MODEL,
        zeta: float = 0.0,
        f1: float | None = None,
        law_params: dict | None = None,
        n: int | None = None,
        **overrides,
    ) -> "System":
        """The paper's friction damper (MODEL.md section 6) in its groups.

        Parameters
        ----------
        eta : float
            N1 / N0 (>= 0).
        beta : float
            mu N0 / F1 (> 0); ignored when ``f1`` is given.
        delta : float
            Normal-load phase, rad.
        model : str
            Contact-law name (:func:`jointdyn.laws.law_names`; default
            ``iwan``, the exact Iwan model; ``iwan-closed``, ``iwan-paper``,
            ``discrete``, ``jenkins``).
        zeta : float
            Viscous damping ratio (paper: 0).
        f1 : float, optional
            Forcing amplitude, N (instead of beta).
        law_params : dict, optional
            Law-specific parameters of ``model``
            (:func:`jointdyn.laws.law_parameters`), e.g. ``{"n": 200}``.
        n : int, optional
            Shorthand for ``law_params={"n": n}`` (elements of ``discrete``);
            a model without that parameter refuses it.
        **overrides
            Any of ``m, k, kt, mu, n0`` (paper values by default).
        """
        p = dict(PAPER)
        for key, val in overrides.items():
            if key not in p:
                raise ValueError(f"unknown parameter {key!r}; allowed: {', '.join(p)}")
            p[key] = val
        law_params = dict(law_params or {})
        if n is not None:
            if "n" in law_params:
                raise ValueError("n is given twice: as n and in law_params; give it once")
            law_params["n"] = n
        law = make_law(model, kt=p["kt"], mu=p["mu"], n_ref=p["n0"], **law_params)
        if f1 is None:
            f1 = law.fy / V.positive("beta", beta)
        return cls.sdof(m=p["m"], k=p["k"], law=law, f1=f1, zeta=zeta, n0=p["n0"], eta=eta, delta=delta)
