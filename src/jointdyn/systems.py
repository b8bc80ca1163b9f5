"""What the system is: mass, damping and stiffness, contacts, forcing.

docs/model.md sections 6 and 8::

    M x'' + C x' + K x + sum_c [Bt_c T_c(u_c, N_c) + Bn_c (N_c - P_c)] = F(t),
    u_c = Bt_c . x,   F_i(t) = f_i sin(w t + phi_i),

with the normal load N_c of each contact either prescribed (constant,
harmonic at the excitation frequency, or a sampled periodic signal) or
produced by the structure through a unilateral normal spring
N_c = max(0, P_c + kn_c Bn_c . x) (:mod:`jointdyn.kinematics`, the one home
of contact selections and normal loads; a prescribed load has no Bn term).

The excitation frequency w is not part of the system: solvers take it (or
gamma = w / w0) as an argument, so one System serves a whole sweep.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from . import _validate as V
from . import config
from ._cache import by_identity
from .damping import ModalDamping
from .interfaces import Interface
from .kinematics import ConstantLoad, HarmonicLoad, NormalLoad, NormalSpring, _selection
from .laws import ContactLaw, make_law

__all__ = ["Contact", "System", "PAPER", "PAPER_NORMAL_DOF", "free_modes", "modal_damping", "rigid_body_modes",
           "stuck_stiffness"]

#: a matrix is positive semi-definite when its smallest eigenvalue is at least -this times
#: its largest (rounding of an assembled singular matrix)
SYSTEM_SEMIDEFINITE_RTOL = 1e-10

#: the paper's section-3 damper (docs/model.md section 6)
PAPER = dict(m=10.0, k=3.9e5, kt=3.0e5, kn=3.0e5, mu=0.5, n0=100.0)
#: the normal DOF of the coupled paper damper (``System.paper_damper(normal="spring")``):
#: mass (kg; light: sqrt(kn / mass) = 27.7 sqrt(k / m)) and damping ratio on kn
PAPER_NORMAL_DOF = dict(mass=0.01, zeta=0.05)


@dataclass(frozen=True)
class Contact:
    """One frictional contact: a tangential law, where it acts, its normal load.

    Parameters
    ----------
    law : ContactLaw
        Tangential law; its ``n_ref`` is the reference load of alpha = N / n_ref.
    dof, dof2 : int
        Tangential relative displacement u = x[dof] - x[dof2]; ``dof2 = -1``
        means against ground.
    normal : NormalLoad, optional
        :class:`~jointdyn.ConstantLoad`, :class:`~jointdyn.HarmonicLoad`,
        :class:`~jointdyn.SampledLoad` or :class:`~jointdyn.NormalSpring`;
        default ``ConstantLoad(law.n_ref)``.
    direction : array_like, optional
        Tangential selection vector over the DOFs (u = direction . x), instead
        of ``dof``/``dof2`` (e.g. for reduced models).
    """

    law: ContactLaw
    dof: int = 0
    dof2: int = -1
    normal: NormalLoad | None = None
    direction: np.ndarray | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.law, ContactLaw):
            raise ValueError(f"law must be a ContactLaw (see jointdyn.make_law), got {type(self.law).__name__}")
        dof, dof2, direction = _selection("tangential", self.dof, self.dof2, self.direction)
        object.__setattr__(self, "dof", dof)
        object.__setattr__(self, "dof2", dof2)
        object.__setattr__(self, "direction", direction)
        normal = ConstantLoad(self.law.n_ref) if self.normal is None else self.normal
        if not isinstance(normal, NormalLoad):
            raise ValueError("normal must be a ConstantLoad, HarmonicLoad, SampledLoad or NormalSpring, "
                             f"got {type(normal).__name__}")
        object.__setattr__(self, "normal", normal)

    @property
    def n0(self) -> float:
        """Static part of the normal load (constant or mean load, or preload), N."""
        return self.normal.n0

    @property
    def n1(self) -> float:
        """Amplitude of a harmonic normal load, N (0 for the other kinds)."""
        return self.normal.n1 if isinstance(self.normal, HarmonicLoad) else 0.0

    @property
    def eta(self) -> float:
        """N1 / N0 of a harmonic normal load (0 for the other kinds)."""
        return self.n1 / self.n0

    @property
    def phase_deg(self) -> float:
        """Phase of a harmonic normal load relative to the forcing, degrees (0 otherwise)."""
        return self.normal.phase_deg if isinstance(self.normal, HarmonicLoad) else 0.0

    def normal_load(self, w: float, t):
        """Prescribed normal load N(t) (N) at times t (s), forcing frequency w (rad/s)."""
        if not self.normal.prescribed:
            raise ValueError("a normal spring's load depends on the motion: it has no N(t) of its own")
        return self.normal.at(w * np.asarray(t, dtype=np.float64))


def _square(name: str, A, n: int) -> np.ndarray:
    A = V.finite_array(name, np.atleast_2d(A), 2)
    if A.shape != (n, n):
        raise ValueError(f"{name} must be {n} x {n}, got shape {A.shape}")
    return A


#: rows compared at once by :func:`asymmetry` (a block of A against the same columns of A: cache-friendly)
_SYMMETRY_BLOCK = 256


def asymmetry(A: np.ndarray) -> tuple[float, int, int]:
    """(max |A - A^T|, i, j where it is reached) of a square matrix, by blocks of rows
    (no n x n temporary; the transposed reads stay in cache)."""
    n = A.shape[0]
    best, where = 0.0, (0, 0)
    for r in range(0, n, _SYMMETRY_BLOCK):
        d = np.abs(A[r:r + _SYMMETRY_BLOCK, :] - A[:, r:r + _SYMMETRY_BLOCK].T)
        k = int(np.argmax(d)) if d.size else 0
        if d.size and d.flat[k] > best:
            best, where = float(d.flat[k]), (r + k // n, k % n)
    return best, where[0], where[1]


def _symmetric(name: str, A: np.ndarray) -> None:
    scale = float(np.max(np.abs(A))) if A.size else 0.0
    diff, i, j = asymmetry(A) if A.ndim == 2 and A.shape[0] == A.shape[1] else (0.0, 0, 0)
    if diff > 1e-10 * scale:
        raise ValueError(f"{name} must be symmetric ({name}[{i},{j}] = {A[i, j]!r} but "
                         f"{name}[{j},{i}] = {A[j, i]!r})")


def _check_selection(what: str, dof: int, dof2: int, direction, n: int) -> None:
    if direction is not None:
        if direction.shape != (n,):
            raise ValueError(f"{what} direction must have length {n} (one entry per DOF), got {direction.size}")
        return
    for d in (dof, dof2):
        if d >= n:
            raise ValueError(f"{what} dof must be in [0, {n - 1}] (or -1 for ground), got {d}")


def _vector(name: str, values, n: int, default: float) -> np.ndarray:
    if values is None:
        return np.full(n, default)
    v = V.finite_array(name, np.atleast_1d(values))
    if v.shape != (n,):
        raise ValueError(f"{name} must have length {n} (one entry per DOF), got {v.size}")
    return v


@dataclass(frozen=True)
class System:
    """Linear structure with frictional contacts and harmonic forcing.

    Parameters
    ----------
    M, C, K : array_like
        Mass (kg, symmetric positive definite), viscous damping (N s/m; None
        for none; :func:`modal_damping` builds one from modal ratios) and
        stiffness (N/m, symmetric) matrices, n x n. C may also be a
        :class:`~jointdyn.damping.ModalDamping` (modal damping kept as an
        operator, ``modal_damping(..., form="operator")``): the solvers apply
        it without an n x n array where the structure is sparse
        (:mod:`jointdyn.damping` lists where it is made dense).
    contacts : tuple of Contact
        The frictional contacts (each with its own law and normal load).
    force : array_like
        Forcing amplitudes f (N) per DOF.
    force_phase_deg : array_like, optional
        Forcing phases phi (degrees) per DOF: F_i(t) = f_i sin(w t + phi_i).
    w0_rad_s : float, optional
        Reference frequency of gamma = w / w0, rad/s (default: see :attr:`w0`).
    output_dof : int, optional
        DOF whose response is reported (default: :attr:`response_dof`).
    interfaces : tuple of Interface
        Contact patches of node pairs with 2-D slip and normal loads from
        the motion (docs/model.md section 10). The quasi-static driver
        (:func:`jointdyn.drivers.interface_loop`) and the time integration
        (:func:`jointdyn.integrate`, :func:`jointdyn.steady_state`) march
        them; harmonic balance and EPMC evaluate them in the AFT
        (:mod:`jointdyn.hb._aft_pairs`); QSMA refuses them.
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    contacts: tuple = field(default_factory=tuple)
    force: np.ndarray = None
    force_phase_deg: np.ndarray = None
    w0_rad_s: float | None = None
    output_dof: int | None = None
    interfaces: tuple = field(default_factory=tuple)

    def __post_init__(self) -> None:
        M = V.finite_array("M", np.atleast_2d(self.M), 2)
        n = M.shape[0]
        if M.shape != (n, n):
            raise ValueError(f"M must be square, got shape {M.shape}")
        _symmetric("M", M)
        if (np.any(np.linalg.eigvalsh(M) <= 0) if n <= config.SYSTEM_DENSE_CHECK_MAX_DOF
                else definiteness_failure(M, semi=False) is not None):  # fmt: skip
            raise ValueError("M must be symmetric positive definite (eigenvalues in (0, inf))")
        K = _square("K", self.K, n)
        _symmetric("K", K)
        if isinstance(self.C, ModalDamping):
            C = self.C
            if C.shape != (n, n):
                raise ValueError(f"C must be {n} x {n}, got a ModalDamping of shape {C.shape}")
        else:
            C = np.zeros((n, n)) if self.C is None else _square("C", self.C, n)
        contacts = tuple(self.contacts)
        for i, c in enumerate(contacts):
            if not isinstance(c, Contact):
                raise ValueError(f"contacts must be Contact instances (contact {i} is a {type(c).__name__})")
            _check_selection(f"contact {i} tangential", c.dof, c.dof2, c.direction, n)
            if isinstance(c.normal, NormalSpring):
                _check_selection(f"contact {i} normal", c.normal.dof, c.normal.dof2, c.normal.direction, n)
        interfaces = tuple(self.interfaces)
        for i, itf in enumerate(interfaces):
            if not isinstance(itf, Interface):
                raise ValueError(f"interfaces must be Interface instances (interface {i} is a {type(itf).__name__})")
            itf.check_ndof(n, f"interface {i}")
        object.__setattr__(self, "interfaces", interfaces)
        for name, value in (("M", M), ("C", C), ("K", K), ("contacts", contacts),
                            ("force", _vector("force", self.force, n, 0.0)),
                            ("force_phase_deg", _vector("force_phase_deg", self.force_phase_deg, n, 0.0))):
            object.__setattr__(self, name, value)
        if self.w0_rad_s is not None:
            object.__setattr__(self, "w0_rad_s", V.positive("w0_rad_s", self.w0_rad_s))
        if self.output_dof is not None:
            d = V.positive_int("output_dof", self.output_dof, 0)
            if d >= n:
                raise ValueError(f"output_dof must be in [0, {n - 1}], got {d}")
            object.__setattr__(self, "output_dof", d)

    @property
    def ndof(self) -> int:
        """Number of degrees of freedom."""
        return self.M.shape[0]

    @property
    def response_dof(self) -> int:
        """DOF whose response is reported: ``output_dof``, else the first
        contact's tangential DOF (its largest selection entry), else 0."""
        if self.output_dof is not None:
            return self.output_dof
        if self.contacts:
            c = self.contacts[0]
            return int(np.argmax(np.abs(c.direction))) if c.direction is not None else c.dof
        return 0

    @property
    def K_reference(self) -> np.ndarray:
        """K with the normal springs in place (closed) and the tangential contacts free, N/m.

        The normal stiffness kn of every interface pair that is closed at
        rest (preload > 0) is in place between its normal DOFs."""
        K = self.K.copy()
        for c in self.contacts:
            if isinstance(c.normal, NormalSpring):
                _add_spring(K, c.normal.kn, _dense(c.normal.dof, c.normal.dof2, c.normal.direction, self.ndof))
        for itf in self.interfaces:
            for (a, b), kn, P in zip(itf.pairs[:, [2, 5]], itf.kn, itf.preload):
                if P > 0.0:  # g = x[a_n] - x[b_n]: the spring kn g^2 / 2
                    v = np.zeros(self.ndof)
                    if a >= 0:
                        v[a] += 1.0
                    if b >= 0:
                        v[b] -= 1.0
                    _add_spring(K, kn, v)
        return K

    @functools.cached_property
    def w0(self) -> float:
        """Reference frequency of gamma = w / w0, rad/s.

        ``w0_rad_s`` when given; else the lowest natural frequency of
        (M, :attr:`K_reference`): normal springs in place, tangential contacts
        free, rigid-body modes (eigenvalues below
        ``config.SYSTEM_RIGID_MODE_RTOL`` times the largest) skipped; 0 when
        every mode is rigid; inf when the frequencies overflow (K / M beyond
        the floating-point range). For the single-DOF damper w0 = sqrt(k/m),
        the paper's reference.
        """
        if self.w0_rad_s is not None:
            return self.w0_rad_s
        if self.ndof > config.SYSTEM_DENSE_CHECK_MAX_DOF:
            w0 = _lowest_elastic_large(self.M, self.K_reference)
            if w0 is not None:
                return w0
        # numpy's LAPACK (already loaded): scipy.linalg would add a third of a second to the CLI's start
        L = np.linalg.cholesky(self.M)
        with np.errstate(over="ignore", invalid="ignore"):
            A = np.linalg.solve(L, np.linalg.solve(L, self.K_reference).T)
            if not np.all(np.isfinite(A)):
                return math.inf  # K / M beyond the floating-point range
            lam = np.linalg.eigvalsh(0.5 * A + 0.5 * A.T)
        elastic = lam[lam > config.SYSTEM_RIGID_MODE_RTOL * lam[-1]]
        return math.sqrt(elastic[0]) if elastic.size and lam[-1] > 0.0 else 0.0

    def require_phase_loads(self, solver: str) -> None:
        """ValueError naming the key if a contact has a sampled normal load
        (for solvers that take constant and harmonic loads and normal springs)."""
        for i, c in enumerate(self.contacts):
            if not isinstance(c.normal, (ConstantLoad, HarmonicLoad, NormalSpring)):
                raise ValueError(f"contact {i} normal: {solver} takes constant and harmonic normal loads and "
                                 f"normal springs, got a {type(c.normal).__name__}")

    def forcing_coefficients(self) -> tuple[np.ndarray, np.ndarray]:
        """(cosine, sine) coefficients of the forcing, N: F = a cos(w t) + b sin(w t)."""
        phi = np.radians(self.force_phase_deg)
        return self.force * np.sin(phi), self.force * np.cos(phi)

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
        delta_deg: float = 0.0,
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
            N1 / N0 (>= 0): N(t) = n0 (1 + eta sin(w t + delta)).
        delta_deg : float
            Normal-load phase relative to the forcing, degrees.
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
            normal = HarmonicLoad(n0=n0, n1=eta * float(n0), phase_deg=delta_deg)
            contacts = (Contact(law=law, dof=0, normal=normal),)
        return cls(M=[[m]], C=[[c]], K=[[k]], contacts=contacts, force=[V.finite("f1", f1)])

    @classmethod
    def paper_damper(
        cls,
        *,
        eta: float = 0.5,
        beta: float = 1.0,
        delta_deg: float = 0.0,
        model: str = config.MODEL,
        zeta: float = 0.0,
        f1: float | None = None,
        law_params: dict | None = None,
        n: int | None = None,
        normal: str = "prescribed",
        normal_mass: float | None = None,
        normal_zeta: float | None = None,
        **overrides,
    ) -> "System":
        """The paper's friction damper (docs/model.md section 6) in its groups.

        With ``normal="prescribed"`` (the paper's model) one DOF x with the
        contact against ground and N(t) = n0 (1 + eta sin(w t + delta)).
        With ``normal="spring"`` the paper's normal spring (``kn``) carries
        the load from a second DOF y (the normal DOF, mass ``normal_mass``,
        no stiffness of its own, viscous damping ratio ``normal_zeta`` on
        kn): N = max(0, n0 + kn y), and y is driven by the normal force
        eta n0 sin(w t + delta), so that a light normal DOF (quasi-static
        normal response) gives N = n0 (1 + eta sin(w t + delta)) while the
        contact stays closed (eta < 1)::

            m x'' + c x' + k x + T(x, N) = f1 sin(w t)
            m_n y'' + c_n y' + (N - n0) = eta n0 sin(w t + delta)

        DOF 0 is x (the output DOF), DOF 1 is y; w0 stays sqrt(k/m).

        Parameters
        ----------
        eta : float
            N1 / N0 (>= 0): the amplitude of the normal load (prescribed) or
            of the normal force on the normal DOF (spring), over n0.
        beta : float
            mu N0 / F1 (> 0); ignored when ``f1`` is given.
        delta_deg : float
            Normal-load (normal-force) phase relative to the forcing, degrees.
        model : str
            Contact-law name (:func:`jointdyn.laws.law_names`; default
            ``iwan``, the exact Iwan model; ``iwan-closed``, ``iwan-paper``,
            ``discrete``, ``jenkins``).
        zeta : float
            Viscous damping ratio of x (paper: 0).
        f1 : float, optional
            Forcing amplitude, N (instead of beta).
        law_params : dict, optional
            Law-specific parameters of ``model``
            (:func:`jointdyn.laws.law_parameters`), e.g. ``{"n": 200}``.
        n : int, optional
            Shorthand for ``law_params={"n": n}`` (elements of ``discrete``);
            a model without that parameter refuses it.
        normal : {"prescribed", "spring"}
            Where the normal load comes from (see above).
        normal_mass : float, optional
            Mass of the normal DOF, kg (> 0; spring only); default
            ``PAPER_NORMAL_DOF["mass"]`` (light: sqrt(kn / m_n) = 27.7 w0).
        normal_zeta : float, optional
            Damping ratio of the normal DOF on kn, c_n = 2 zeta sqrt(kn m_n)
            (>= 0; spring only); default ``PAPER_NORMAL_DOF["zeta"]``.
        **overrides
            Any of ``m, k, kt, kn, mu, n0`` (paper values by default).
        """
        p = dict(PAPER)
        for key, val in overrides.items():
            if key not in p:
                raise ValueError(f"unknown parameter {key!r}; allowed: {', '.join(p)}")
            p[key] = val
        V.choice("normal", normal, ("prescribed", "spring"))
        if normal == "prescribed" and (normal_mass is not None or normal_zeta is not None):
            raise ValueError('normal_mass and normal_zeta need normal="spring"')
        law_params = dict(law_params or {})
        if n is not None:
            if "n" in law_params:
                raise ValueError("n is given twice: as n and in law_params; give it once")
            law_params["n"] = n
        law = make_law(model, kt=p["kt"], mu=p["mu"], n_ref=p["n0"], **law_params)
        if f1 is None:
            f1 = law.fy / V.positive("beta", beta)
        if normal == "prescribed":
            return cls.sdof(m=p["m"], k=p["k"], law=law, f1=f1, zeta=zeta, n0=p["n0"], eta=eta,
                            delta_deg=delta_deg)  # fmt: skip
        return _coupled_damper(cls, p, law, f1=V.finite("f1", f1), zeta=V.nonnegative("zeta", zeta),
                               eta=V.nonnegative("eta", eta), delta_deg=V.finite("delta_deg", delta_deg),
                               m_n=PAPER_NORMAL_DOF["mass"] if normal_mass is None else normal_mass,
                               zeta_n=PAPER_NORMAL_DOF["zeta"] if normal_zeta is None else normal_zeta)  # fmt: skip


def _coupled_damper(cls, p, law, *, f1, zeta, eta, delta_deg, m_n, zeta_n) -> System:
    """The paper damper with its normal spring on a normal DOF (``System.paper_damper(normal="spring")``)."""
    m, k, kn, n0 = V.positive("m", p["m"]), V.positive("k", p["k"]), V.positive("kn", p["kn"]), p["n0"]
    m_n = V.positive("normal_mass", m_n)
    c_n = 2.0 * V.nonnegative("normal_zeta", zeta_n) * math.sqrt(kn * m_n)
    spring = NormalSpring(kn=kn, preload=n0, dof=1)
    return cls(M=np.diag([m, m_n]), C=np.diag([2.0 * zeta * math.sqrt(k * m), c_n]), K=np.diag([k, 0.0]),
               contacts=(Contact(law=law, dof=0, normal=spring),), force=[f1, eta * n0],
               force_phase_deg=[0.0, delta_deg], w0_rad_s=math.sqrt(k / m), output_dof=0)  # fmt: skip


#: a matrix with at most this fraction of non-zero entries is factorised and multiplied as a
#: sparse one by the checks of large structures (assembled finite-element matrices are)
_SPARSE_FRACTION = 0.05


def _operator(A: np.ndarray):
    """``A`` as a scipy.sparse CSC matrix when it is sparse enough, else itself."""
    import scipy.sparse as sp

    if np.count_nonzero(A) <= _SPARSE_FRACTION * A.size:
        return sp.csc_matrix(A)
    return A


def _largest_eigenvalue(A, M=None) -> float:
    """Largest eigenvalue of A (or of the pencil (A, M)) by Lanczos iterations (eigsh), to 1e-3: a scale
    for the tolerances of the semi-definite and rigid-mode tests."""
    from scipy.sparse.linalg import eigsh

    return float(eigsh(A, k=1, M=M, which="LA", return_eigenvectors=False, tol=1e-3)[0])


def _positive_definite(A) -> bool:
    """Whether the symmetric ``A`` (dense, or scipy.sparse) is positive definite: a dense Cholesky
    factorisation, or a sparse symmetric LDL^T one (SuperLU, diagonal pivots: the signs of the pivots are
    the signs of the eigenvalues, Sylvester's law of inertia)."""
    import scipy.sparse as sp

    if not sp.issparse(A):
        import scipy.linalg as sl

        try:
            sl.cholesky(A, lower=True, overwrite_a=True, check_finite=False)
            return True
        except np.linalg.LinAlgError:
            return False
    from scipy.sparse.linalg import splu

    try:
        lu = splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                  options=dict(SymmetricMode=True))
    except RuntimeError:  # an exactly singular pivot
        return False
    return bool(np.all(lu.perm_r == lu.perm_c)) and bool(np.all(lu.U.diagonal() > 0.0))


def definiteness_failure(A: np.ndarray, *, semi: bool) -> float | None:
    """None when the symmetric ``A`` is positive definite (``semi``: positive
    semi-definite, its smallest eigenvalue at least -``SYSTEM_SEMIDEFINITE_RTOL``
    times its largest); else its smallest eigenvalue.

    Scales to large matrices: a Cholesky factorisation (of A shifted by the
    tolerance when ``semi``, the largest eigenvalue by Lanczos iterations)
    decides, no eigen-decomposition; the smallest eigenvalue is computed
    only for the message of a matrix that fails.
    """
    import scipy.sparse as sp

    n = A.shape[0]
    op = _operator(A)
    shift = 0.0
    if semi:
        shift = SYSTEM_SEMIDEFINITE_RTOL * max(abs(_largest_eigenvalue(op)) if n > 2 else
                                                       float(np.max(np.abs(np.linalg.eigvalsh(A)))), 1e-300)
    if sp.issparse(op):
        B = op + shift * sp.identity(n, format="csc")
    else:
        B = np.array(A, dtype=np.float64, order="F")
        B[np.diag_indices(n)] += shift
    if _positive_definite(B):
        return None
    del B
    from scipy.sparse.linalg import ArpackError, eigsh

    try:
        return float(eigsh(op, k=1, which="SA", return_eigenvectors=False)[0])
    except (ArpackError, ValueError):
        return float(np.linalg.eigvalsh(A)[0])


def rigid_mode_dof(K: np.ndarray) -> int | None:
    """None when the symmetric positive semi-definite ``K`` has no mode with an eigenvalue at most
    ``config.SYSTEM_RIGID_MODE_RTOL`` times its largest (no rigid-body mode); else the DOF that takes
    the largest part of such a mode. Dense eigen-decomposition up to
    ``config.SYSTEM_DENSE_CHECK_MAX_DOF`` DOFs, else a shifted Cholesky factorisation and Lanczos
    iterations (the mode only for a matrix that has one)."""
    n = K.shape[0]
    if n <= config.SYSTEM_DENSE_CHECK_MAX_DOF:
        lam, vec = np.linalg.eigh(0.5 * K + 0.5 * K.T)
        return None if lam[0] > config.SYSTEM_RIGID_MODE_RTOL * abs(lam[-1]) else int(np.argmax(np.abs(vec[:, 0])))
    op = _operator(K)
    shift = config.SYSTEM_RIGID_MODE_RTOL * abs(_largest_eigenvalue(op))
    if definiteness_failure(K - shift * np.eye(n), semi=False) is None:
        return None
    from scipy.sparse.linalg import eigsh

    _, vec = eigsh(op, k=1, sigma=-shift, which="LM")
    return int(np.argmax(np.abs(vec[:, 0])))


def loose_dofs(K: np.ndarray) -> np.ndarray:
    """The DOFs whose row of the stiffness ``K`` (N/m) is zero, int array: joined to nothing (a free-free
    assembly's rigid-body modes move DOFs joined to others; a DOF joined to nothing is a forgotten
    stiffness far more often than a free body, and the solvers that take free-free structures refuse it)."""
    return np.flatnonzero(~np.any(np.asarray(K) != 0.0, axis=1))


def rigid_body_modes(K: np.ndarray, M: np.ndarray) -> np.ndarray:
    """The rigid-body modes of (M, K): (n, r) with Phi^T M Phi = I (kg^-1/2), r = 0 when there is none.

    A mode is rigid when its eigenvalue of (M, K) is at most ``config.SYSTEM_RIGID_MODE_RTOL`` times the
    largest (the rule of :func:`rigid_mode_dof`, on the pencil). Up to ``config.SYSTEM_DENSE_CHECK_MAX_DOF``
    DOFs a Cholesky factorisation of K less the tolerance times a bound of its largest eigenvalue says
    "none" for a structure held in place, else a dense eigen-decomposition; beyond, shift-invert Lanczos
    iterations asked for more modes until one is elastic. The modes found are M-orthonormalised
    (Cholesky of Phi^T M Phi)."""
    n = K.shape[0]
    if n <= config.SYSTEM_DENSE_CHECK_MAX_DOF:
        Ks = 0.5 * K + 0.5 * K.T
        # no rigid-body mode when K less the tolerance times a bound of its largest eigenvalue (the largest
        # absolute row sum) is positive definite: one Cholesky factorisation, a fraction of an eigensolve
        shift = config.SYSTEM_RIGID_MODE_RTOL * float(np.max(np.sum(np.abs(Ks), axis=1)))
        try:
            np.linalg.cholesky(Ks - shift * np.eye(n))
            return np.zeros((n, 0))
        except np.linalg.LinAlgError:
            pass
        from scipy.linalg import eigh

        lam, vec = eigh(Ks, M)
        phi = vec[:, lam <= config.SYSTEM_RIGID_MODE_RTOL * abs(lam[-1])]
    else:
        from scipy.sparse.linalg import eigsh

        if rigid_mode_dof(K) is None:
            return np.zeros((n, 0))
        top = abs(_largest_eigenvalue(_operator(K), _operator(M)))
        k = 8
        while True:
            lam, vec = eigsh(_operator(K), k=min(k, n - 1), M=_operator(M), sigma=-config.SYSTEM_RIGID_MODE_RTOL * top,
                             which="LM")
            rigid = lam <= config.SYSTEM_RIGID_MODE_RTOL * top
            if not np.all(rigid) or k >= n - 1:
                break
            k *= 2
        phi = vec[:, rigid]
    if phi.shape[1] == 0:
        return np.zeros((n, 0))
    L = np.linalg.cholesky(phi.T @ M @ phi)
    return np.ascontiguousarray(np.linalg.solve(L, phi.T).T)


@by_identity
def free_modes(system) -> np.ndarray:
    """The rigid-body modes of ``system`` with every contact and every interface pair closed at rest stuck
    (:func:`stuck_stiffness`): (n, r), M-orthonormal (kg^-1/2), r = 0 for a structure held in place
    (cached per System). A free-free assembly (a bolted beam hung on bungees) has r > 0: 6 in 3-D, 3 in
    2-D, 1 for a chain along its axis. The contacts and pairs cannot act on such a mode (their springs
    hold it by nothing: b^T Phi = 0), nor can K: their forces balance."""
    return rigid_body_modes(stuck_stiffness(system), system.M)


def _lowest_elastic_large(M: np.ndarray, K: np.ndarray) -> float | None:
    """Lowest elastic natural frequency (rad/s) of (M, K) by shift-invert Lanczos
    iterations: the few lowest eigenvalues, more until one is elastic (above
    ``SYSTEM_RIGID_MODE_RTOL`` of the largest); 0 when every mode is rigid;
    None when the iterations fail (the caller decomposes densely)."""
    from scipy.sparse.linalg import ArpackError, eigsh

    n = M.shape[0]
    K, M = _operator(K), _operator(M)
    try:
        top = _largest_eigenvalue(K, M)
        if not top > 0.0:
            return 0.0
        k = 6
        while k < n - 1:
            lam = np.sort(eigsh(K, k=k, M=M, sigma=-config.SYSTEM_RIGID_MODE_RTOL * top, which="LM",
                                return_eigenvectors=False))
            elastic = lam[lam > config.SYSTEM_RIGID_MODE_RTOL * top]
            if elastic.size:
                return math.sqrt(elastic[0])
            k *= 4
    except (ArpackError, ValueError, np.linalg.LinAlgError):
        return None
    return None


def _dense(dof: int, dof2: int, direction, n: int) -> np.ndarray:
    """Selection vector (n,) of (dof, dof2) or ``direction``."""
    if direction is not None:
        return np.asarray(direction, dtype=np.float64).copy()
    b = np.zeros(n)
    b[dof] += 1.0
    if dof2 >= 0:
        b[dof2] -= 1.0
    return b


def modal_damping(M, K, zeta, *, form: str = "array"):
    """Viscous damping with modal damping ratios, N s/m.

    ``C = M Phi diag(2 zeta_r w_r) Phi^T M`` with the mass-normalised modes
    Phi and natural frequencies w_r (rad/s) of (M, K), so that mode r of the
    undamped structure (M, K) has damping ratio zeta_r. Pass the stiffness the
    ratios refer to: :func:`stuck_stiffness` of a System (every contact and
    interface pair stuck, normal springs closed: the structure a modal test
    measures at low level) or ``System.K_reference`` (normal springs in place,
    tangential contacts free).

    Parameters
    ----------
    M, K : array_like (n, n)
        Mass (kg, symmetric positive definite) and stiffness (N/m, symmetric).
    zeta : float or array_like (n,)
        Damping ratio of every mode, or one per mode in increasing frequency
        (>= 0). Rigid-body modes (w_r = 0) get no damping.
    form : {"array", "operator"}
        ``"array"`` (default): the dense n x n ndarray. ``"operator"``: a
        :class:`~jointdyn.damping.ModalDamping` that applies C in O(n^2)
        without forming it, which :class:`System` takes as its C (harmonic
        balance and EPMC of a sparse structure then keep their Jacobians
        sparse); ``.toarray()`` gives the same array as ``"array"``.
    """
    from scipy.linalg import eigh

    V.choice("form", form, ("array", "operator"))
    M = V.finite_array("M", np.atleast_2d(M), 2)
    K = V.finite_array("K", np.atleast_2d(K), 2)
    n = M.shape[0]
    _square("K", K, n)
    _symmetric("M", M)
    _symmetric("K", K)
    z = np.atleast_1d(np.asarray(zeta, dtype=np.float64))
    if z.size == 1:
        z = np.full(n, float(z[0]))
    if z.shape != (n,) or not np.all(np.isfinite(z)) or np.any(z < 0):
        raise ValueError(f"zeta must be a number >= 0 or {n} numbers >= 0 (one per mode), got {zeta!r}")
    lam, phi = eigh(K, M)
    w = np.sqrt(np.maximum(lam, 0.0))
    op = ModalDamping(M, phi, z, w, lam=lam, stiffness=K)
    return op if form == "operator" else op.toarray()


def stuck_stiffness(system) -> np.ndarray:
    """Stiffness (n, n) N/m of ``system`` at rest with every contact and every interface pair closed at
    rest stuck (their kt, kn in place: :func:`static_springs`): the structure whose modes a modal test
    measures at low amplitude."""
    K = np.array(system.K, dtype=np.float64)
    for _, k, b in static_springs(system):
        _add_spring(K, k, b)
    return K


def _add_spring(K: np.ndarray, k: float, b: np.ndarray) -> None:
    """K += k b b^T in place, on the rows and columns where b is nonzero only (the same sums: the other
    entries would add zeros), so that the springs of hundreds of node pairs cost O(pairs), not O(pairs n^2)."""
    idx = np.flatnonzero(b)
    K[np.ix_(idx, idx)] += k * np.outer(b[idx], b[idx])


def static_springs(system, open_pairs: bool = False) -> list:
    """The springs that hold a System at rest with every contact stuck and every normal spring
    closed, beside its K: ``(key, stiffness N/m, selection vector)`` each, the key as a system
    file names it (``contact[i].kt``, ``contact[i].normal.kn``, ``interface[i].kt`` or ``.kn``,
    pairs counted from 0). Pairs open at rest (preload 0) hold nothing: with ``open_pairs`` they are
    the only ones listed (the springs they would add once closed)."""
    n = system.ndof
    out = []
    for i, c in enumerate(() if open_pairs else system.contacts):
        out.append((f"contact[{i}].kt", float(c.law.kt), _dense(c.dof, c.dof2, c.direction, n)))
        kn = getattr(c.normal, "kn", None)
        if kn is not None:
            nm = c.normal
            out.append((f"contact[{i}].normal.kn", float(kn), _dense(nm.dof, nm.dof2, nm.direction, n)))
    for i, itf in enumerate(system.interfaces):
        for j, row in enumerate(itf.pairs):
            if (itf.preload[j] > 0.0) == open_pairs:
                continue
            for k, (name, value) in enumerate((("kt", itf.kt[j]), ("kt", itf.kt[j]), ("kn", itf.kn[j]))):
                b = np.zeros(n)
                if row[k] >= 0:
                    b[row[k]] += 1.0
                if row[k + 3] >= 0:
                    b[row[k + 3]] -= 1.0
                out.append((f"interface[{i}].{name}" + (f" (pair {j})" if itf.npairs > 1 else ""), float(value), b))
    return out
