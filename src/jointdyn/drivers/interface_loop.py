"""Quasi-static loops of an interface: its node pairs under prescribed relative histories.

docs/model.md section 10. Each pair of an :class:`~jointdyn.interfaces.Interface`
is given its relative tangential displacement (u1, u2) and normal approach g
as functions of time; inertia plays no part, so time only orders the
samples. Between samples the histories are taken linear and the element is
exact along them (docs/model.md section 10); every instant where the normal
load ``P + kn g`` of a pair changes sign is also inserted as a sample, so
that the metrics (the work by the trapezoidal rule, the open fraction) see
separation and re-contact at their instants. Each
full period is a cycle; the result gives, per pair and for the last full
cycle, the work of the tangential force (the energy dissipated per cycle on
a closed steady cycle) and the fractions of the cycle the pair sticks,
slips and is open.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .. import config
from ..interfaces import Interface, interface_march
from ..laws import MACROSLIP, SEPARATION, STICK_SLIP
from ..status import Status
from .quasistatic import _interval_states, cycle_count

__all__ = ["InterfaceLoopResult", "InterfaceLoopStatus", "interface_loop"]


class InterfaceLoopStatus(Status):
    """Status of a quasi-static interface loop."""

    OK = "ok", "every pair marched over the whole history; metrics of the last full cycle", True
    OPEN = "open", "no pair closes in the last full cycle: its forces and energy are 0", True


@dataclass(frozen=True, eq=False)
class InterfaceLoopResult:
    """Response of an interface to prescribed relative histories.

    Attributes
    ----------
    t : ndarray (nt,)
        Times of the marched history, s (input samples and inserted crossings).
    u : ndarray (nt, npairs, 2)
        Relative tangential displacements, m.
    g : ndarray (nt, npairs)
        Normal approaches, m.
    T : ndarray (nt, npairs, 2)
        Tangential forces, N.
    N : ndarray (nt, npairs)
        Normal loads, N.
    code : ndarray of int8 (nt, npairs)
        Motion state per sample and pair: STICK_SLIP (stuck), MACROSLIP (slipping), SEPARATION.
    inserted : ndarray of bool (nt,)
        True at the samples inserted where a pair's normal load changes sign.
    period : float or None
        Cycle length, s (None: the whole history is one cycle).
    cycle_energy_J : ndarray (ncycles,)
        Work of the tangential forces of all pairs over each full cycle, J.
    pair_energy_J : ndarray (npairs,)
        Work of each pair's tangential force over the last full cycle, J
        (on a closed steady cycle: the energy it dissipates per cycle).
    stick_fraction, slip_fraction, open_fraction : ndarray (npairs,)
        Fractions of the last full cycle each pair sticks, slips and is open
        (they sum to 1; open is timed exactly, the contact part of each step
        gets the state at its end).
    t_start_s, t_end_s : float
        The last full cycle, s.
    state : ndarray (npairs, 2)
        Committed sliders after the last sample, m.
    status : InterfaceLoopStatus
        ``ok``, or ``open`` when no pair closes in the last full cycle.
    """

    t: np.ndarray
    u: np.ndarray
    g: np.ndarray
    T: np.ndarray
    N: np.ndarray
    code: np.ndarray
    inserted: np.ndarray
    period: float | None
    cycle_energy_J: np.ndarray
    pair_energy_J: np.ndarray
    stick_fraction: np.ndarray
    slip_fraction: np.ndarray
    open_fraction: np.ndarray
    t_start_s: float
    t_end_s: float
    state: np.ndarray
    status: InterfaceLoopStatus

    @property
    def n_cycles(self) -> int:
        """Number of full cycles analysed."""
        return int(self.cycle_energy_J.size)

    @property
    def n_inserted(self) -> int:
        """Number of inserted crossing samples."""
        return int(np.count_nonzero(self.inserted))

    @property
    def energy_J(self) -> float:
        """Work of the tangential forces of all pairs over the last full cycle, J (the last entry of
        ``cycle_energy_J``)."""
        return float(self.cycle_energy_J[-1])


def _histories(interface: Interface, t, u1, u2, g):
    """Validated histories, broadcast to (nt, npairs)."""
    t = V.finite_array("t", t)
    if t.size < 2:
        raise ValueError(f"t must have at least 2 samples, got {t.size}")
    V.increasing("t", t)
    out = []
    for name, a in (("u1", u1), ("u2", u2), ("g", g)):
        ndim = np.ndim(a) if np.ndim(a) in (1, 2) else 1
        arr = V.finite_array(name, a, ndim)
        if arr.shape[0] != t.size:
            raise ValueError(f"{name} must have one row per sample of t ({t.size}), got {arr.shape[0]}")
        if arr.ndim == 1:
            arr = np.repeat(arr[:, None], interface.npairs, axis=1)
        elif arr.shape[1] != interface.npairs:
            raise ValueError(f"{name} must have one column per pair ({interface.npairs}), got {arr.shape[1]}")
        out.append(np.ascontiguousarray(arr))
    return t, out[0], out[1], out[2]


def _insert_crossings(t, chans, nlin):
    """Insert the instants where a column of ``nlin`` (linear in t) changes sign strictly
    between two samples (instants closer than ``config.QS_SNAP_RTOL`` of the duration merged);
    every channel (rows = samples) is interpolated linearly there."""
    pos, neg = nlin > 0.0, nlin < 0.0
    j, i = np.nonzero((pos[:-1] & neg[1:]) | (neg[:-1] & pos[1:]))
    if j.size == 0:
        return t, chans, np.zeros(t.size, dtype=bool)
    r = nlin[j, i] / (nlin[j, i] - nlin[j + 1, i])
    tc = np.unique(t[j] + r * (t[j + 1] - t[j]))
    # pairs that cross together (the same instant up to rounding) share one sample
    keep = np.concatenate(([True], np.diff(tc) > config.QS_SNAP_RTOL * (t[-1] - t[0])))
    tc = tc[keep]
    k = np.searchsorted(t, tc, side="right") - 1  # interval of each instant
    inside = (k >= 0) & (k < t.size - 1) & (tc > t[np.clip(k, 0, t.size - 1)])
    inside &= tc < t[np.clip(k + 1, 0, t.size - 1)]
    tc, k = tc[inside], k[inside]
    if tc.size == 0:
        return t, chans, np.zeros(t.size, dtype=bool)
    rr = (tc - t[k]) / (t[k + 1] - t[k])
    new = []
    for a in chans:
        sh = (-1,) + (1,) * (a.ndim - 1)
        new.append(np.insert(a, k + 1, a[k] + rr.reshape(sh) * (a[k + 1] - a[k]), axis=0))
    inserted = np.insert(np.zeros(t.size, dtype=bool), k + 1, True)
    return np.insert(t, k + 1, tc), new, inserted


def _refine(t, chans, code, bounds):
    """Insert the cycle bounds as samples (channels linear in t; the code of the step's end, or of its
    start where the end is open)."""
    tol = config.QS_SNAP_RTOL * (t[-1] - t[0])
    new_t = [b for b in bounds if not np.any(np.abs(t - b) <= tol)]
    if not new_t:
        return t, chans, code
    new_t = np.asarray(new_t)
    j = np.searchsorted(t, new_t)
    r = (new_t - t[j - 1]) / (t[j] - t[j - 1])
    out = []
    for a in chans:
        sh = (-1,) + (1,) * (a.ndim - 1)
        out.append(np.insert(a, j, a[j - 1] + r.reshape(sh) * (a[j] - a[j - 1]), axis=0))
    ins_code = np.where(code[j] != SEPARATION, code[j], code[j - 1]).astype(code.dtype)
    return np.insert(t, j, new_t), out, np.insert(code, j, ins_code, axis=0)


def _window(t, u, T, sep, contact, i0, i1):
    """Per-pair tangential work (J) and stick / slip / open fractions over samples i0..i1."""
    dt = np.diff(t[i0 : i1 + 1])[:, None]
    total = t[i1] - t[i0]
    Tm = 0.5 * (T[i0:i1] + T[i0 + 1 : i1 + 1])
    work = np.sum(Tm * np.diff(u[i0 : i1 + 1], axis=0), axis=(0, 2))
    s, c = sep[i0:i1], contact[i0:i1]
    f_open = np.sum(dt * s, axis=0) / total
    f_slip = np.sum(dt * (1.0 - s) * (c == MACROSLIP), axis=0) / total
    f_stick = np.sum(dt * (1.0 - s) * (c == STICK_SLIP), axis=0) / total
    return work, f_stick, f_slip, f_open


def interface_loop(interface, t, u1, u2, g, *, period=None, state=None) -> InterfaceLoopResult:
    """March an interface over prescribed relative histories and measure its loops.

    Every pair is stepped sample by sample (docs/model.md section 10) from its
    virgin slider at ``(u1[0], u2[0])`` (or ``state``). The histories are
    linear between samples; each instant where a pair's ``P + kn g`` changes
    sign strictly between two samples is inserted as a sample of every pair.

    Cycle k is ``[t[0] + k period, t[0] + (k + 1) period]`` for every full
    period in the history (without ``period`` the whole history is one
    cycle); bounds between samples are interpolated linearly for the metrics.
    Per cycle the work of the tangential forces is the trapezoidal integral
    of ``T . du``: on a closed steady cycle the energy dissipated (the
    normal springs store and return theirs).

    Parameters
    ----------
    interface : Interface
        The pairs and their parameters.
    t : array_like (nt,)
        Times, s (finite, strictly increasing, at least 2).
    u1, u2 : array_like (nt,) or (nt, npairs)
        Relative tangential displacements, m: one history for every pair, or one column per pair.
    g : array_like (nt,) or (nt, npairs)
        Normal approaches, m (positive closes).
    period : float, optional
        Cycle length, s (see :func:`jointdyn.drivers.cycle_count` for the allowed range).
    state : array_like (npairs, 2), optional
        Committed sliders to start from, m (default: virgin, w = u at t[0]).

    Returns
    -------
    InterfaceLoopResult

    Raises
    ------
    ValueError
        Bad input, naming the parameter.
    """
    if not isinstance(interface, Interface):
        raise ValueError(f"interface must be a jointdyn.interfaces.Interface, got {type(interface).__name__}")
    t, u1, u2, g = _histories(interface, t, u1, u2, g)
    ncyc = None if period is None else cycle_count(t, V.positive("period", period))
    p = interface.params
    nlin = p[:, 3] + p[:, 1] * g
    t, (u1, u2, g, nlin), inserted = _insert_crossings(t, [u1, u2, g, nlin], nlin)
    U = np.ascontiguousarray(np.stack([u1, u2], axis=2))
    w0 = np.ascontiguousarray(U[0]) if state is None else interface.check_state(state)
    nt, npairs = g.shape
    T = np.empty((nt, npairs, 2))
    N = np.empty((nt, npairs))
    code = np.empty((nt, npairs), dtype=np.int8)
    w_final = np.empty((npairs, 2))
    interface_march(p, w0, U, g, T, N, code, w_final)
    t0 = float(t[0])
    bounds = [t0, float(t[-1])] if ncyc is None else [t0 + k * period for k in range(ncyc + 1)]
    bounds[-1] = min(bounds[-1], float(t[-1]))
    tr, (Ur, Tr, nr), cr = _refine(t, [U, T, nlin], code, bounds)
    sep, contact = _interval_states(nr, cr)
    tol = config.QS_SNAP_RTOL * (tr[-1] - tr[0])
    energies = []
    for k in range(len(bounds) - 1):
        i0 = int(np.searchsorted(tr, bounds[k] - tol))
        i1 = int(np.searchsorted(tr, bounds[k + 1] + tol, side="right")) - 1
        work, f_stick, f_slip, f_open = _window(tr, Ur, Tr, sep, contact, i0, i1)
        energies.append(float(np.sum(work)))
    closes = np.any(nr[i0 : i1 + 1] > 0.0)
    status = InterfaceLoopStatus.OK if closes else InterfaceLoopStatus.OPEN
    return InterfaceLoopResult(
        t=t, u=U, g=g, T=T, N=N, code=code, inserted=inserted, period=None if period is None else float(period),
        cycle_energy_J=np.asarray(energies), pair_energy_J=work, stick_fraction=f_stick, slip_fraction=f_slip,
        open_fraction=f_open, t_start_s=float(tr[i0]), t_end_s=float(tr[i1]), state=w_final, status=status,
    )
