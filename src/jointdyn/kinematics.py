"""Contact kinematics: how the structure's motion reaches a contact and back.

This module is the one home of the contact geometry and of the normal load:
the tangential (and normal) selection of each contact from the structure's
degrees of freedom, the normal load as a function of time and state, and
the kernels that stand in for "no contact" in compiled loops of systems
without contacts (they are not a contact law and are registered nowhere).
"""

from __future__ import annotations

from ._jit import jit

__all__ = ["no_contact_step", "no_contact_step_jvp", "no_contact_init", "no_contact_init_jvp"]


@jit
def no_contact_step(params, s_old, s_new, x, N):  # pragma: no cover - never reached
    """Kernel bound in compiled loops of systems without contacts (no force)."""
    return 0.0, 0.0, 0


@jit
def no_contact_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):  # pragma: no cover
    """Forward-mode twin of :func:`no_contact_step` (no force, no derivative)."""
    for j in range(dT.shape[0]):
        dT[j] = 0.0
    return 0.0, 0.0, 0


@jit
def no_contact_init(params, x0, n0, s):  # pragma: no cover - never reached
    """Virgin state of :func:`no_contact_step` (empty)."""
    for r in range(s.shape[0]):
        s[r] = 0.0


@jit
def no_contact_init_jvp(params, x0, dx0, n0, dn0, s, ds):  # pragma: no cover - never reached
    """:func:`no_contact_init` with derivatives (all zero)."""
    for r in range(s.shape[0]):
        s[r] = 0.0
        for j in range(ds.shape[1]):
            ds[r, j] = 0.0
