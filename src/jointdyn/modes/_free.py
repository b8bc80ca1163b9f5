"""What nonlinear modes need from a System: free vibration, the linear stuck mode, scales.

A nonlinear mode is a free vibration: nothing in it may be prescribed at a
forcing frequency. Normal loads that are functions of the forcing phase (a
:class:`~jointdyn.HarmonicLoad` with ``n1 > 0``, a
:class:`~jointdyn.SampledLoad`) are refused, naming the contact and the
reason; a constant load (also a harmonic load with ``n1 = 0``) and a normal
spring (``load.autonomous``) have a place in a free vibration. Whether a
solver evaluates a normal spring is the solver's business (EPMC: the
harmonic-balance contact evaluation; QSMA: refused, its Masing construction
needs constant normal loads).

The linear **stuck** mode (every contact a spring kt, normal springs in
place) starts every backbone: mode ``K`` (1-based, increasing frequency)
of ``(M, K_reference + sum_c kt_c b_c b_c^T)``. Of a free-free structure
(that stiffness has rigid-body modes: :func:`jointdyn.systems.free_modes`)
the modes are counted among the elastic ones: mode 1 is the first elastic
mode, the rigid-body modes are never chosen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .. import config
from .._cache import by_identity
from ..kinematics import HarmonicLoad, NormalSpring
from ..hb.problem import stuck_stiffness
from ..systems import System, free_modes, loose_dofs

__all__ = ["LinearMode", "check_free_vibration", "linear_stuck_mode", "output_dof_of", "amplitude_range",
           "contact_scale"]

#: a DOF moves in a linear mode when |phi_dof| exceeds this fraction of max |phi|
MODES_MIN_PARTICIPATION = 1e-8
#: K (tangential contacts free) is positive definite for nonlinear modes when
#: its smallest eigenvalue of (M, K) exceeds this fraction of the largest
MODES_MIN_EIGENVALUE_RATIO = 1e-12


@dataclass(frozen=True)
class LinearMode:
    """A linear mode of the structure with every contact stuck.

    Attributes
    ----------
    index : int
        Mode number, 1-based, in increasing frequency, among the elastic modes (a free-free structure's
        rigid-body modes are not counted).
    omega_rad_s : float
        Natural frequency, rad/s.
    shape : ndarray (n,)
        Mode shape scaled to 1 at the output DOF (dimensionless).
    mass_normalised : ndarray (n,)
        The same shape with phi^T M phi = 1, kg^-1/2.
    stiffness : ndarray (n, n)
        The stuck stiffness K_reference + sum_c kt_c b_c b_c^T, N/m.
    repeated : tuple of int
        The other modes (1-based) with the same frequency to a relative
        ``REPEATED_RTOL``: a repeated eigenvalue, whose mode shape is any
        combination of theirs (empty for an isolated mode).
    """

    index: int
    omega_rad_s: float
    shape: np.ndarray
    mass_normalised: np.ndarray
    stiffness: np.ndarray
    repeated: tuple[int, ...] = ()


#: Relative difference of two squared natural frequencies below which the eigenvalue is repeated: a few
#: thousand times the rounding of a symmetric eigensolver, far below any physical detuning.
REPEATED_RTOL = 1e-10


def _constant(load) -> bool:
    """True for a load that does not change in time (a harmonic load with n1 = 0 included)."""
    return isinstance(load, HarmonicLoad) and load.n1 == 0.0


def check_free_vibration(system, method: str, *, springs: bool = True, held: bool = False) -> System:
    """``system`` if it describes a free vibration with frictional contacts; ValueError otherwise.

    Parameters
    ----------
    system : System
    method : str
        Name of the method, for the messages (``"EPMC"``, ``"QSMA"``).
    springs : bool
        Whether the method takes normal springs and interfaces (node pairs, whose normal loads follow the
        motion): QSMA takes neither.
    held : bool
        Whether the method takes a structure held only through its contacts (K with the tangential contacts
        free singular, the stuck stiffness not: :func:`jointdyn.hb.problem.held_by_contacts`) and a free-free
        one (the stuck stiffness has rigid-body modes, :func:`jointdyn.systems.free_modes`, and no DOF is
        joined to nothing): EPMC does (its harmonic balance restarts the laws at the preloaded static state
        and gauges the rigid-body part of the mean), and so does QSMA (its push starts from the stuck
        structure and holds the rigid-body part of the push at zero by the same gauge).
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    if system.interfaces and not springs:
        npairs = sum(itf.npairs for itf in system.interfaces)
        raise ValueError(f"system: has interfaces ({npairs} node pairs), which {method} does not support (its "
                         "Masing construction holds for scalar contacts at constant normal loads): use EPMC for "
                         "this system")
    if not system.contacts and not (springs and system.interfaces):
        raise ValueError(f"system must have at least one contact: {method} computes the modes of a structure "
                         "with frictional contacts")
    for i, c in enumerate(system.contacts):
        load = c.normal
        if _constant(load):
            continue
        if not load.autonomous:
            what = (f"a harmonic load with n1 = {load.n1:g} N" if isinstance(load, HarmonicLoad)
                    else f"a {type(load).__name__}")
            raise ValueError(
                f"contact {i}: its normal load is {what}, prescribed at a forcing frequency; a nonlinear mode is "
                "a free vibration, which has no forcing frequency: give a constant normal load (ConstantLoad) "
                "or a normal spring (NormalSpring)")
        if isinstance(load, NormalSpring) and not springs:
            raise ValueError(
                f"contact {i}: {method} takes constant normal loads only (its Masing construction holds when "
                "the slip limits do not change), and a normal spring makes the load follow the motion: use "
                "EPMC for this system")
    lam = _reference_eigenvalues(system)
    if held and not _resolved(lam):
        # held only through the contacts: the stuck structure must be held (a DOF held by nothing is refused)
        Ks = stuck_stiffness(system)
        lam = stuck_modes(system)[0]
        if _resolved(lam):
            return system
        r = free_modes(system).shape[1]
        if 0 < r < lam.size and not loose_dofs(Ks).size and _resolved(lam[r:]):
            # free-free: the stuck structure's rigid-body modes are never chosen, its mean gauged by harmonic
            # balance; ill-conditioned stiffnesses and pairs open at rest are refused below
            from ..hb import check_mean_position

            try:
                check_mean_position(system)
                return system
            except ValueError:
                pass
        what = ("is ill-conditioned with every contact stuck: its smallest eigenvalue of (M, K), "
                f"{lam[0]:.6g} (rad/s)^2, is {lam[0] / lam[-1]:.3g} of the largest, below the ratio "
                f"{MODES_MIN_EIGENVALUE_RATIO:g} that double precision resolves (a normal stiffness kn many "
                "decades below the others?)" if lam[0] > 0.0 else
                "must be positive definite with every contact stuck (smallest eigenvalue of (M, K + kt + kn) "
                f"{lam[0]:.6g} (rad/s)^2: a DOF held by nothing)")
        raise ValueError(f"K {what}: {method} needs a static equilibrium of the stuck structure")
    if not _resolved(lam):
        # a positive eigenvalue below the ratio is a stiffness too small beside the others, not a free DOF
        what = ("is ill-conditioned with the tangential contacts free: its smallest eigenvalue of (M, K), "
                f"{lam[0]:.6g} (rad/s)^2, is {lam[0] / lam[-1]:.3g} of the largest, below the ratio "
                f"{MODES_MIN_EIGENVALUE_RATIO:g} that double precision resolves (a normal stiffness kn many "
                "decades below the others?)" if lam[0] > 0.0 else
                "must be positive definite with the tangential contacts free (smallest eigenvalue of (M, K) "
                f"{lam[0]:.6g} (rad/s)^2)")
        raise ValueError(f"K {what}: {method} needs a static equilibrium of the slipping structure (the mean "
                         "of the motion is not held by friction)")
    return system


def _resolved(lam) -> bool:
    """True when the smallest eigenvalue ``lam[0]`` of (M, K) is above ``MODES_MIN_EIGENVALUE_RATIO``
    of the largest (K positive definite, as double precision resolves it)."""
    return bool(lam[0] > MODES_MIN_EIGENVALUE_RATIO * abs(lam[-1]))


def output_dof_of(system: System, output_dof) -> int:
    """The output DOF: ``output_dof`` (validated) or the system's response DOF."""
    if output_dof is None:
        return system.response_dof
    d = V.positive_int("output_dof", output_dof, 0)
    if d >= system.ndof:
        raise ValueError(f"output_dof must be in [0, {system.ndof - 1}], got {output_dof!r}")
    return d


@by_identity
def _reference_eigenvalues(system: System) -> np.ndarray:
    """Eigenvalues of (K_reference, M), (rad/s)^2, ascending (cached per System: the checks of a
    backbone ask for them more than once, a dense eigensolve each at the size of a reduced model)."""
    from scipy.linalg import eigh

    return eigh(system.K_reference, system.M, eigvals_only=True)


@by_identity
def stuck_modes(system: System) -> tuple[np.ndarray, np.ndarray]:
    """(eigenvalues (rad/s)^2 ascending, M-orthonormal eigenvectors) of the stuck structure
    (:func:`~jointdyn.hb.problem.stuck_stiffness`, M), cached per System; callers must not modify them."""
    from scipy.linalg import eigh

    return eigh(stuck_stiffness(system), system.M)


def linear_stuck_mode(system: System, mode: int, output_dof: int) -> LinearMode:
    """Mode ``mode`` (1-based) of the stuck structure, scaled to 1 at ``output_dof``.

    Raises
    ------
    ValueError
        ``mode`` out of [1, n], or the output DOF does not move in that mode.
    """
    n = system.ndof
    r = free_modes(system).shape[1]  # rigid-body modes of a free-free structure: never chosen, not counted
    k = V.positive_int("mode", mode, 1)
    if k > n - r:
        what = f"{n} DOFs" if r == 0 else f"{n - r} elastic modes beside its {r} rigid-body modes"
        raise ValueError(f"mode must be in [1, {n - r}] (the system has {what}), got {mode!r}")
    Ks = stuck_stiffness(system)
    lam, phi = stuck_modes(system)
    lam, phi = lam[r:], phi[:, r:]  # the elastic modes, in increasing frequency
    v = phi[:, k - 1].copy()
    big = float(np.max(np.abs(v)))
    if not abs(v[output_dof]) > MODES_MIN_PARTICIPATION * big:
        raise ValueError(f"output_dof: DOF {output_dof} does not move in linear stuck mode {k} "
                         f"(|phi| = {abs(v[output_dof]):.3g} of {big:.3g}); choose a DOF that moves in it")
    if v[output_dof] < 0:
        v = -v
    scale = max(abs(lam[k - 1]), float(np.max(np.abs(lam))) * np.finfo(float).eps)
    repeated = tuple(int(j) + 1 for j in np.flatnonzero(np.abs(lam - lam[k - 1]) <= REPEATED_RTOL * scale)
                     if j != k - 1)
    return LinearMode(index=k, omega_rad_s=math.sqrt(max(lam[k - 1], 0.0)), shape=v / v[output_dof],
                      mass_normalised=v, stiffness=Ks, repeated=repeated)


def contact_scale(system: System) -> float:
    """fy / kt of the first contact, else of the interfaces' patch (m): the displacement scale of the default
    amplitudes (:func:`jointdyn.hb.problem.reference_scales`)."""
    from ..hb.problem import reference_scales

    kt, fy = reference_scales(system)
    return fy / kt


def amplitude_range(system: System, amplitude) -> tuple[float, float]:
    """(smallest, largest) amplitude in m: ``amplitude`` validated, or the default range.

    The default is ``config.MODES_AMPLITUDE_Q`` times fy / kt of the first
    contact.
    """
    if amplitude is None:
        scale = contact_scale(system)
        if not scale > 0.0:
            why = ("the first contact has no friction (fy = 0)" if system.contacts else
                   "every interface pair is open at rest (mu x preload = 0: no slip force)")
            raise ValueError(f"amplitude must be given (min, max) in m: {why}, so there is no default range")
        lo, hi = (q * scale for q in config.MODES_AMPLITUDE_Q)
        return lo, hi
    try:
        lo, hi = amplitude
    except (TypeError, ValueError):
        raise ValueError(f"amplitude must be a pair (min, max) of amplitudes in m, got {amplitude!r}") from None
    lo = V.positive("amplitude min", lo)
    hi = V.positive("amplitude max", hi)
    if not hi > lo:
        raise ValueError(f"amplitude max must be > min ({lo:g} m), got {hi:g} m")
    V.derived("log10(amplitude max / amplitude min)", math.log10(hi / lo), positive=True)
    return lo, hi
