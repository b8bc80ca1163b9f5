"""Re-contact of a contact between two AFT samples: where its normal load closes, and the displacement there.

Where a contact re-closes between two samples of the harmonic-balance AFT
(:mod:`jointdyn.hb._aft`), the law is restarted virgin at the exact
re-contact phase, at the displacement there, before it steps to the next
sample, so that the re-contact instant is not quantised to the sampling
grid. For a prescribed normal load the phases are found once per
evaluation from its harmonic coefficients (:func:`recontact_events`); for a
normal spring, whose load follows the solution, inside the march
(:func:`_spring_event`). Both give the displacement at the event and its
derivative along the harmonic coefficients (:func:`_event_point`).
"""

from __future__ import annotations

import numpy as np

from .._jit import jit

__all__ = ["recontact_events", "NO_EVENT"]

#: phase of an event table entry without a re-contact in the interval before the sample
NO_EVENT = -1.0

#: load at which the AFT restarts a contact law at a re-contact phase between
#: two samples, as a fraction of the contact's largest |N| (> 0: the law is
#: in contact and at rest there, as the time integrator's default
#: ``MarchOptions.recontact_alpha`` of :mod:`jointdyn.dynamics.options`)
HB_RECONTACT_ALPHA = 1e-12
#: Newton iterations and relative step (of the sampling interval) of a spring's re-contact root
_ROOT_MAX_ITER, _ROOT_TOL = 50, 1e-14


@jit
def _event_point(U, tau, dtau, has_p, dx):  # pragma: no cover - compiled
    """Displacement at phase ``tau`` of the signal with coefficients ``U``; its derivative into ``dx``.

    ``dx[h]`` (h < 2H+1) is the basis function h at ``tau`` (the derivative
    along coefficient h; the entries of the normal approach's coefficients,
    if any, are left as they are: zero); with ``has_p`` the last entry is
    ``u'(tau) dtau``,
    the derivative along the parameter through the phase (``dtau`` its
    derivative). A plain compiled function, called once per event.
    """
    nh = U.shape[0]
    x = U[0]
    du = 0.0
    dx[0] = 1.0
    for k in range(1, (nh - 1) // 2 + 1):
        ck = np.cos(k * tau)
        sk = np.sin(k * tau)
        dx[2 * k - 1] = ck
        dx[2 * k] = sk
        x += U[2 * k - 1] * ck + U[2 * k] * sk
        du += k * (U[2 * k] * ck - U[2 * k - 1] * sk)
    if has_p:
        dx[dx.shape[0] - 1] = du * dtau
    return x


@jit
def _trig(C, tau):  # pragma: no cover - compiled
    """(f, f') at phase ``tau`` of the signal with coefficients ``C`` (constant, cos, sin, ...)."""
    f = C[0]
    df = 0.0
    for k in range(1, (C.shape[0] - 1) // 2 + 1):
        ck = np.cos(k * tau)
        sk = np.sin(k * tau)
        f += C[2 * k - 1] * ck + C[2 * k] * sk
        df += k * (C[2 * k] * ck - C[2 * k - 1] * sk)
    return f, df


@jit
def _spring_event(U, G, sp, tau1, h, g0, g1, dx):  # pragma: no cover - compiled
    """Re-contact of a spring between the phases ``tau1 - h`` and ``tau1``: displacement there, derivative into ``dx``.

    The root tau_r of v(tau) = P + kn g(tau) (v <= 0 at ``tau1 - h`` where
    g = ``g0``, v > 0 at ``tau1`` where g = ``g1``) by Newton's method kept
    inside the bracket (regula falsi where a step leaves it), to rounding.
    Returns u(tau_r); ``dx`` gets its derivative along the coefficients of
    u (the basis at tau_r, entries 0..nh-1) and of g (entries nh..2nh-1:
    u'(tau_r) dtau_r/dG_h with dtau_r/dG_h = -Q_h(tau_r) / g'(tau_r)). A
    plain compiled function, called once per event.
    """
    P0, kn = sp[0], sp[1]
    a, b = tau1 - h, tau1
    va, vb = P0 + kn * g0, P0 + kn * g1
    t = a - va * (b - a) / (vb - va)
    for _ in range(_ROOT_MAX_ITER):
        g, dg = _trig(G, t)
        v = P0 + kn * g
        if v > 0.0:
            b, vb = t, v
        else:
            a, va = t, v
        tn = t - v / (kn * dg) if dg != 0.0 else a - 1.0
        if not a < tn < b:
            tn = a - va * (b - a) / (vb - va)
        if abs(tn - t) <= _ROOT_TOL * h:
            t = tn
            break
        t = tn
    x = _event_point(U, t, 0.0, False, dx)
    du = _trig(U, t)[1]
    dg = _trig(G, t)[1]
    nh = U.shape[0]
    for d in range(nh):
        dx[nh + d] = -du * dx[d] / dg if dg != 0.0 else 0.0
    return x


def recontact_events(tau, coefficients, derivatives=None, uniform: bool = True):
    """Re-contact phases of harmonic normal loads inside the sampling intervals.

    For N = n0 + n1 sin(tau + delta) the contact re-closes where N crosses
    zero upwards, at ``tau_r = -delta - asin(n0 / |n1|)`` (mod 2 pi, with
    ``delta`` shifted by pi for n1 < 0) when |n0| < |n1|. The event is
    attached to the first sample after it, ``tau_i > tau_r``, if the load
    there is positive (a re-contact exactly on a sample, or a contact
    shorter than the interval, needs none: the step at that sample
    handles it).

    Parameters
    ----------
    tau : ndarray (Ns,)
        Increasing sample phases in [0, 2 pi), rad: the uniform ones
        2 pi j / Ns, or (``uniform=False``) any, starting at 0.
    coefficients : ndarray (contacts, 3)
        (n0, n1, delta) per contact (N, N, rad).
    derivatives : ndarray (contacts, 3), optional
        Their derivatives along the continuation parameter.
    uniform : bool
        ``tau`` are the uniform phases (the sample is found from the
        sampling interval), else the first phase after the crossing is
        searched.

    Returns
    -------
    ev_tau, ev_dtau : ndarray (contacts, Ns)
        Re-contact phase in the interval before each sample (rad;
        :data:`NO_EVENT` where none) and its derivative along the
        parameter.
    ev_load : ndarray (contacts,)
        Load at which the law restarts there (N): ``HB_RECONTACT_ALPHA``
        times the largest |N| of the contact (> 0, so that the law is in
        contact, at rest).

    Notes
    -----
    A normal load produced by the structure (a normal spring) crosses
    zero at phases that depend on the unknowns: the same table applies,
    with the root of the spring's load polynomial in each interval and
    its derivative along every unknown.
    """
    co = np.atleast_2d(np.asarray(coefficients, dtype=np.float64))
    nc, ns = co.shape[0], tau.size
    ev_tau = np.full((nc, ns), NO_EVENT)
    ev_dtau = np.zeros((nc, ns))
    ev_load = np.zeros(nc)
    h = 2.0 * np.pi / ns
    for c in range(nc):
        n0, n1, delta = co[c]
        ev_load[c] = HB_RECONTACT_ALPHA * (abs(n0) + abs(n1))
        a1 = abs(n1)
        if not abs(n0) < a1:
            continue
        dl = delta + (np.pi if n1 < 0.0 else 0.0)
        r = n0 / a1
        tr = (-dl - np.arcsin(r)) % (2.0 * np.pi)
        if uniform:
            i = int(np.ceil(tr / h))
            if i * h <= tr:  # rounding: the sample must lie after the crossing
                i += 1
        else:
            i = int(np.searchsorted(tau, tr, side="right"))
        i %= ns
        if n0 + n1 * np.sin(tau[i] + delta) <= 0.0:
            continue
        ev_tau[c, i] = tr
        if derivatives is not None:
            dn0, dn1, ddelta = np.asarray(derivatives, dtype=np.float64)[c]
            dr = dn0 / a1 - n0 * np.sign(n1) * dn1 / (a1 * a1)
            ev_dtau[c, i] = -ddelta - dr / np.sqrt(1.0 - r * r)
    return ev_tau, ev_dtau, ev_load
