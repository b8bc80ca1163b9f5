"""Rigid-body modes in harmonic balance: parts held only through their contacts, free-free structures.

Two kinds of structure have rigid-body modes that the contacts decide about:

* parts held only through their contacts (:func:`held_by_contacts`): K with
  the tangential contacts free has more rigid-body modes than the stuck
  structure; harmonic balance restarts the laws at the preloaded static
  state, so that a stuck contact holds the parts' relative mean position;
* a free-free structure (a bolted beam hung on bungees): the stuck
  structure itself has rigid-body modes Phi_r (:func:`jointdyn.systems.free_modes`);
  harmonic balance fixes their part of the mean at zero (:func:`mean_gauge`).

Both may hold at once (two free beams joined by a lap joint).
"""

from __future__ import annotations

import numpy as np

from .._cache import by_identity
from ..systems import System, free_modes, rigid_body_modes, rigid_mode_dof

__all__ = ["held_by_contacts", "mean_gauge"]


@by_identity
def held_by_contacts(system: System) -> bool:
    """True when ``system`` is held only through its contacts: ``System.K_reference`` (K with the normal
    springs closed, the tangential contacts free) has more rigid-body modes
    (:func:`jointdyn.systems.rigid_body_modes`) than the stuck structure
    (:func:`jointdyn.systems.stuck_stiffness`: every contact and pair stuck), which has none for a
    structure held in place and those of the whole assembly for a free-free one; cached per System.

    Such a part (a beam joined to another by a bolted joint, a friction damper held by its contacts) is at
    rest in the preloaded static state, the origin of the coordinates, where every contact is at rest
    without tangential force. Harmonic balance then restarts each law there instead of at the mean of its
    motion (:attr:`HBProblem.restart_at_reference`): a stuck contact's force is kt u, its mean holds the
    part, and only a part that slides as a whole through the cycle has no unique mean position.
    """
    if not (system.contacts or system.interfaces):
        return False
    if rigid_mode_dof(system.K_reference) is None:
        return False
    # a free-free assembly: its parts held through the contacts when freeing them adds rigid-body modes
    return rigid_body_modes(system.K_reference, system.M).shape[1] > free_modes(system).shape[1]


def mean_gauge(system: System, w0: float):
    """s M Phi_r Phi_r^T M (n, n), N/m, with Phi_r the rigid-body modes of the stuck structure
    (:func:`jointdyn.systems.free_modes`, M-orthonormal) and s = w0^2; None for a structure held in place.

    Harmonic balance adds it to K on harmonic 0 alone (the mean), the only harmonic where the rigid-body
    modes make the linear part singular (k w != 0 elsewhere). The contacts, the pairs and K exert no force
    along Phi_r (their forces are internal and balance) and the forcing f sin(w t + phi) has no mean, so
    Phi_r^T of the mean equation reads s Phi_r^T M x_0 = 0: the gauge fixes the rigid-body part of the mean
    at zero (the free body stays where it was, on average) and changes nothing else. At the harmonics
    k >= 1 the rigid-body modes respond to the forcing as free masses (-k^2 w^2 Phi_r^T M Phi_r), as in a
    free-free FRF measurement."""
    phi = free_modes(system)
    if phi.shape[1] == 0:
        return None
    mp = np.asarray(system.M, dtype=np.float64) @ phi
    return (w0 * w0) * (mp @ mp.T)
