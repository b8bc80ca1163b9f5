"""Period map of the forced structure and its finite-difference monodromy matrix.

The period map marches (x, v) over one forcing period with the RK4 core
(the same compiled runner as :func:`~jointdyn.dynamics.integrate`), the
contact law states carried from a given committed state; a perturbation of
the displacements acts on the contacts as a motion from that state. Its
Jacobian, the monodromy matrix, is taken by finite differences in
:func:`fd_monodromy`, the one routine that both shooting (Newton on the
period map in :func:`~jointdyn.dynamics.steady_state`) and the monodromy
check of harmonic-balance solutions
(:func:`jointdyn.hb.monodromy.monodromy_multipliers`) use. The map is
piecewise smooth (stick-slip transitions, reversals and separation are
located exactly inside the steps), so a relative step of about 1e-6 gives
the multipliers to about that accuracy.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as V
from ._model import Model, make_model
from .options import MarchOptions, march_with_steps

__all__ = ["fd_monodromy", "period_map", "monodromy_matrix"]

#: relative central-difference step of the monodromy check of harmonic-balance
#: solutions (of the amplitude for displacements, of w times it for velocities)
MONODROMY_FD_STEP = 1e-6


def fd_monodromy(pmap, z, scale, eps: float, z1=None):
    """Monodromy matrix of a map by finite differences, in the coordinates z / scale.

    Column j is ``(P(z + eps scale_j e_j) - z1) / scale / eps`` (forward
    differences, when ``z1 = P(z)`` is given) or
    ``(P(z + eps scale_j e_j) - P(z - eps scale_j e_j)) / scale / (2 eps)``
    (central differences). Its eigenvalues are those of dP/dz.

    Parameters
    ----------
    pmap : callable
        ``P(z) -> ndarray`` (same length as z), or None where the map fails.
    z : ndarray
        Point of differentiation.
    scale : ndarray
        Positive scale of each coordinate (same units as z).
    eps : float
        Relative step (> 0).
    z1 : ndarray, optional
        ``P(z)`` (forward differences); None for central differences.

    Returns
    -------
    ndarray (m, m) or None
        None when the map failed at a perturbed point.
    """
    m = z.size
    J = np.empty((m, m))
    for j in range(m):
        e = eps * scale[j]
        zp = z.copy()
        zp[j] += e
        zj = pmap(zp)
        if zj is None:
            return None
        if z1 is not None:
            J[:, j] = (zj - z1) / scale / eps
            continue
        zm = z.copy()
        zm[j] -= e
        zk = pmap(zm)
        if zk is None:
            return None
        J[:, j] = (zj - zk) / scale / (2.0 * eps)
    return J


def period_map(model: Model, grid, states, rdof: int = 0, book=None):
    """The map (x, v) -> (x, v) over ``grid`` (one period from its first point).

    Every evaluation starts from a copy of the committed law ``states``;
    ``book(result)`` (optional) receives each :class:`~jointdyn.dynamics._model.RunResult`.
    Returns a callable ``P(z)``, z = (x, v) (m, m/s), giving None on a blow-up.
    """
    n = model.n

    def pmap(z):
        x = z[:n].copy()
        v = z[n:].copy()
        res = model.run_grid(x, v, states.copy(), grid, 1, rdof)
        if book is not None:
            book(res)
        if not res.status.ok or res.done < 1:
            return None
        return np.concatenate([x, v])

    return pmap


def monodromy_matrix(system, w: float, t0: float, x, v, states, *, amplitude: float,
                     eps: float | None = None, steps_per_period: int | None = None,
                     march: MarchOptions | None = None) -> np.ndarray:  # fmt: skip
    """Monodromy matrix of the harmonically forced system over one period from time t0.

    Parameters
    ----------
    system : System
        The structure, contacts and forcing.
    w : float
        Forcing frequency, rad/s (> 0).
    t0 : float
        Start of the period (Poincare section), s.
    x, v : array_like
        State at t0 (m, m/s).
    states : array_like
        Committed law states at t0, one row per contact.
    amplitude : float
        Displacement scale (m) of the perturbations: relative step ``eps``
        of ``amplitude`` for x and of ``w amplitude`` for v.
    eps : float, optional
        Relative step of the central differences (default ``MONODROMY_FD_STEP``).
    steps_per_period : int, optional
        RK4 base steps per period (default ``march.steps_per_period``, 256); replaces that field.
    march : MarchOptions, optional
        The numbers of the time march (:class:`~jointdyn.dynamics.options.MarchOptions`; None: the
        defaults).

    Returns
    -------
    ndarray (2n, 2n)
        d(x, v)(t0 + T) / d(x, v)(t0) in coordinates scaled by (amplitude, w amplitude);
        its eigenvalues are the Floquet multipliers.

    Raises
    ------
    ValueError
        For a non-positive w or amplitude, or when the integration blows up.
    """
    w = V.positive("w", w)
    amp = V.positive("amplitude", amplitude)
    eps = V.positive("eps", MONODROMY_FD_STEP if eps is None else eps)
    model = make_model(system, w, march_with_steps(march, steps_per_period))
    n = model.n
    ta = float(t0) % model.period
    grid = model.segment_grid(ta, ta + model.period)
    S = np.ascontiguousarray(np.array(states, dtype=np.float64, ndmin=2))
    z = np.concatenate([np.asarray(x, dtype=float), np.asarray(v, dtype=float)])
    scale = np.concatenate([np.full(n, amp), np.full(n, amp * w)])
    J = fd_monodromy(period_map(model, grid, S), z, scale, eps)
    if J is None:
        raise ValueError("the period map blew up at a perturbed state (amplitude or eps too large)")
    return J
