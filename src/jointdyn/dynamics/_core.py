"""Compiled time-stepping core (templates specialised per contact law).

Scheme: classical explicit Runge-Kutta (RK4) on ``y = (x, v, E_c, E_v, W, I_x)``
with the contact forces evaluated at every stage as a *trial step* of the
law from the committed state (kernel contract, laws/_base.py). At the end of
an accepted step the law is evaluated once more at the end displacement and
that trial is committed (buffer swap); the same evaluation gives the first
stage of the next step (first-same-as-last).

Events are never smeared over a step:

* step boundaries are put exactly at the zero crossings of every prescribed
  N_c(t) (the grid passed in contains them, with N snapped to exactly 0 at a
  separation and to a tiny positive value at a re-contact, so that the
  committed law state is "separated" resp. "virgin at the re-contact point");
* when the relative velocity of any contact changes sign inside a step, the
  instant of the extremum of u is located on the cubic Hermite interpolant
  of (u, du) over the step, the step is redone up to that instant and
  committed there, so that the law's reversal point is the true extremum;
* when P + kn g of a normal spring (g: the normal approach, from the state)
  changes sign inside a step, the instant is located the same way on the
  Hermite interpolant of (g, dg), the step is redone up to it and the load
  committed there is snapped like a prescribed one (0 at the separation,
  a tiny positive value at the re-contact), so that the law separates and
  restarts virgin at the located instants;
* when the motion state of a contact changes inside a step (onset or end of
  macroslip), the instant is located by bisection on the law's state code
  and the step is redone up to there.

A normal spring acts on the structure with ``Bn (N - P)`` (N = max(0,
P + kn g)), the tangential law with ``Bt T``; the contact power counted as
dissipation is that of T alone (the spring is conservative).

Interface pairs (docs/model.md section 10) are marched alongside: every
evaluation steps all pairs from their committed sliders along the straight
path from the committed point (u0, g0) to the stage point
(:func:`jointdyn.interfaces.interface_step`, bound as ``PAIR_STEP``), the
accepted step's end is committed (sliders, point, codes). Each pair's
velocity reversals of u1, u2 and its openings and closings (P + kn g
changes sign on the Hermite interpolant of g) split the step as a
contact's do, in one pass over the pairs (cost linear in their number);
stick/slip changes inside a step are not located (the kernel is exact
along the straight path). The power T . du of each pair is integrated with
the RK4 weights (one entry of y per pair, after the four integrals), so
that the per-pair dissipation adds up to the contacts' total; the time
each pair spends stuck, slipping and open is booked at every commit. The
sliders live in the rows of the law-state array after the contacts' rows
(two numbers per pair, row after row).

The runner is one loop around a single evaluation of the right-hand side
(law trial steps included), so that the law kernel is compiled inline once;
an *evaluation kind* (``EVAL_*``) says what the evaluation is for (the
start, RK stages 2..4, the end of the step, a bisection probe), and small
helpers inlined by Numba do one job each: the stage time and the probe
state, the RK combination, the reversal and spring-event split, the loads
of sampled grids, the spring loads and reactions, the linear forces and the
stage derivatives, the state-change test and the bisection, commit and
record, the period summary. Two rules keep the loop as fast as a
hand-written one (both measured):

* the law kernel is called in the template's body, not inside a helper
  (inlined, the call measured 3.5x slower);
* a helper called at every evaluation takes arrays (not tuples), has no
  branch on which array it touches and creates no array view: otherwise
  the reference counts of its arguments, which Numba updates at every
  inlined call, are not optimised away (1.3 to 2x slower).

The spring, phase and pair work is compiled only for systems that have
normal springs, forcing phases or interfaces (global flags ``SPRINGS``,
``PHASED`` and ``INTERFACES`` bound with the kernel), so other systems run
the loop they ran without it.

The runner takes five grouped arguments (tuples of arrays):

``system``  ``(Minv, K, C, (f_sin, f_cos), kin, P, (pairs, pair_params))``: inverse mass matrix,
            stiffness and damping matrices, forcing amplitudes (mode
            LOADS_HARMONIC: F = f_sin sin(w t) + f_cos cos(w t)), the contact
            kinematics tuple (:mod:`jointdyn.kinematics`) and the law
            parameter rows (:mod:`jointdyn.laws._dispatch`), the interface
            pairs' DOFs (np, 6) and parameters kt, kn, mu, P (np, 4)
``grid``    ``(t, N, F, (sin_mid, sin_end, cos_mid, cos_end), N_mid)``: step
            grid (s), prescribed normal loads (N) at its points, sampled
            forcing F (N; mode LOADS_SAMPLED), forcing sines and cosines at
            the midpoint and end of every step and prescribed loads at the
            midpoints (mode LOADS_HARMONIC)
``control`` ``(mode, repetitions, phase0, w, rdof, max_split, record, recontact)``
            (``recontact``: the load committed at a spring's re-contact, as
            a fraction of its preload)
``io``      ``(x, v, S, cap)``: state in and out (S: committed law states,
            one row per contact, then the pairs' sliders) and the blow-up
            caps of (x, v)
``out``     ``(t, x, v, T, N, code, summary, z_end, pairs)``: recorded samples
            and the per-repetition summary (columns ``S_*``; ``S_OPEN``
            counts the steps that end with a spring contact open or in
            which a pair opened or closed), end states and per pair (repetitions, np, 4) its work (J)
            and the fractions of the repetition it was stuck, slipping, open

It returns ``(samples recorded, run status RUN_*, repetitions done)``
(samples: ``capacity + 1`` with RUN_OVERFLOW when the buffers were full).
The template calls the global placeholders ``STEP`` (the law kernel, or
the mixed-law dispatcher), reads ``SPRINGS`` and ``PHASED`` and calls ``PRESCRIBED_LOAD``
(:func:`jointdyn.kinematics.prescribed_load`, bound so that the compiled
copy's cache name follows the kinematics source, whose helpers are
compiled into it) and is compiled per kernel with
:func:`jointdyn._jit.specialize`. Where inside a step an event lies (Hermite
interpolation, crossings, the split guards) is :mod:`._step_events`; the node
pairs of interfaces are :mod:`._pairs`.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import jit
from ..kinematics import (
    NORMAL_SPRING,
    apply_normal_force,
    apply_tangential_force,
    prescribed_load,
    spring_load,
    tangential,
)
from ..laws._base import SEPARATION
from ._pairs import _pair_point, _pair_reactions, _pair_split, _pair_workspace, _pairs_commit
from ._step_events import _BISECT_PROBES, _SPLIT_GUARD, _crossing, _hermite_root, _hermite_value

# columns of the per-period summary
S_XMAX, S_XMIN, S_EC, S_EV, S_W, S_XMEAN, S_STEPS, S_OPEN = range(8)
N_SUMMARY = 8

#: run status (compiled codes; :class:`~jointdyn.dynamics.RunStatus` names them)
RUN_OK, RUN_BLOWUP, RUN_OVERFLOW = 0, 1, 2

#: load modes: harmonic forcing and normal loads, or sampled (piecewise linear)
LOADS_HARMONIC, LOADS_SAMPLED = 0, 1

#: evaluation kinds: the initial evaluation, RK stages 2..4 of the current
#: attempt, the end of the step (commit), a bisection probe
EVAL_START, EVAL_STAGE2, EVAL_STAGE3, EVAL_STAGE4, EVAL_END, EVAL_PROBE = -1, 0, 1, 2, 3, 4

#: rows of the stage table: RK stages 1..4, end of step (= stage 1 of the
#: next step), bisection probe
ROW_END, ROW_PROBE, N_ROWS = 4, 5, 6

# --- where to evaluate -----------------------------------------------------------


@jit(inline="always")
def _probe_state(sm, h, y0, y1, ys, n):  # pragma: no cover - compiled
    """(x, v) at fraction ``sm`` of the step on the cubic Hermite interpolant
    (x) and the linear one (v)."""
    for i in range(n):
        ys[i] = _hermite_value(y0[i], y1[i], y0[n + i], y1[n + i], h, sm)
        ys[n + i] = y0[n + i] + sm * (y1[n + i] - y0[n + i])


@jit(inline="always")
def _stage_time(e, t0, h, tc, end_idx):  # pragma: no cover - compiled
    """(time s, grid index or -1, stage offset a s) of evaluation ``e`` (not a probe)."""
    if e == EVAL_START:
        return t0, 0, 0.0
    if e == EVAL_END:
        return tc + h, end_idx, h
    a_ = 0.5 * h if e < EVAL_STAGE4 else h
    return tc + a_, end_idx if e == EVAL_STAGE4 else -1, a_


@jit(inline="always")
def _rk4_combine(y0, kk, h, y1, ys):  # pragma: no cover - compiled
    """End of the RK4 step: y1 = y0 + h/6 (k1 + 2 k2 + 2 k3 + k4), also into
    ys (the state of the end-of-step evaluation)."""
    for r in range(y1.shape[0]):
        y1[r] = y0[r] + h / 6.0 * (kk[0, r] + 2.0 * kk[1, r] + 2.0 * kk[2, r] + kk[3, r])
        ys[r] = y1[r]


@jit(inline="always")
def _reversal_fraction(tan_idx, tan_w, y0, y1, h, n):  # pragma: no cover - compiled
    """Earliest velocity reversal of any contact inside the step, as a fraction
    of the step (Hermite root); 2.0 when there is none away from the ends."""
    sbest = 2.0
    for c in range(tan_idx.shape[0]):
        du0 = tangential(tan_idx, tan_w, c, y0, n)
        du1 = tangential(tan_idx, tan_w, c, y1, n)
        if du0 * du1 < 0.0:
            u0 = tangential(tan_idx, tan_w, c, y0, 0)
            u1 = tangential(tan_idx, tan_w, c, y1, 0)
            sr = _hermite_root(u0, u1, du0, du1, h)
            if sr > _SPLIT_GUARD and sr < 1.0 - _SPLIT_GUARD and sr < sbest:
                sbest = sr
    return sbest


@jit(inline="always")
def _spring_event(n_par, n_idx, n_w, c, y0, y1, h, n):  # pragma: no cover - compiled
    """:func:`_crossing` of spring contact c inside the step (normal approach
    g from the states y0, y1)."""
    g0 = tangential(n_idx, n_w, c, y0, 0)
    g1 = tangential(n_idx, n_w, c, y1, 0)
    dg0 = tangential(n_idx, n_w, c, y0, n)
    dg1 = tangential(n_idx, n_w, c, y1, n)
    return _crossing(n_par[c, 0], n_par[c, 1], g0, g1, dg0, dg1, h)


@jit
def _spring_split(n_kind, n_par, n_idx, n_w, y0, y1, h, n, recontact, sbest):  # pragma: no cover - compiled
    """Earliest opening or closing of a normal spring inside the step, if it
    comes before ``sbest`` (the earliest velocity reversal, a fraction of the
    step) and lies away from the ends.

    Returns (fraction, the spring contact whose event it is or -1, the load
    committed there: 0 at a separation, ``recontact`` times the preload at a
    re-contact). A plain compiled function, called only by runners of
    systems with springs: inlined, the event search costs every runner
    about 1.5 s of compilation.
    """
    ev_c = -1
    ev_n = 0.0
    for c in range(n_kind.shape[0]):
        if n_kind[c] == NORMAL_SPRING:
            sr, rising = _spring_event(n_par, n_idx, n_w, c, y0, y1, h, n)
            if sr > _SPLIT_GUARD and sr < 1.0 - _SPLIT_GUARD and sr < sbest:
                sbest = sr
                ev_c = c
                ev_n = recontact * n_par[c, 0] if rising else 0.0
    return sbest, ev_c, ev_n


# --- loads at a time ---------------------------------------------------------------


@jit(inline="always")
def _add_cosines(fcos, cp, Fv):  # pragma: no cover - compiled
    """Fv_i += fcos_i cos(w t) (``cp`` = cos(w t)): the out-of-phase part of the forcing, N."""
    for i in range(Fv.shape[0]):
        Fv[i] += fcos[i] * cp


@jit(inline="always")
def _springs(n_kind, n_par, n_idx, n_w, ys, Nv, ev_c, ev_n, work):  # pragma: no cover - compiled
    """Loads of the spring contacts from the state ys, and their reactions:
    work -= Bn_c (N_c - P_c) (N). Contact ``ev_c`` (>= 0 at the end of a
    step split at its spring event) gets ``ev_n`` instead (exactly open at a
    separation, about to load at a re-contact)."""
    for c in range(Nv.shape[0]):
        if n_kind[c] == NORMAL_SPRING:
            Nv[c] = ev_n if c == ev_c else spring_load(n_par, n_idx, n_w, c, ys)
            apply_normal_force(n_idx, n_w, c, Nv[c] - n_par[c, 0], work)


@jit(inline="always")
def _sampled_row(tgrid, table, tau, gidx, j, out):  # pragma: no cover - compiled
    """Sampled loads at tau: the table row at a grid point, else linear between
    the grid points j and j + 1 (sampled grids only: it branches on the table
    row, which costs reference counting at every call)."""
    if gidx >= 0:
        for c in range(out.shape[0]):
            out[c] = table[gidx, c]
    else:
        al = (tau - tgrid[j]) / (tgrid[j + 1] - tgrid[j])
        for c in range(out.shape[0]):
            out[c] = table[j, c] + al * (table[j + 1, c] - table[j, c])


# --- right-hand side: M x'' = F - C v - K x - sum_c B_c T_c -----------------------------


@jit(inline="always")
def _linear_forces(K, C, ys, Fv, n, work):  # pragma: no cover - compiled
    """work = F - C v - K x, N."""
    for i in range(n):
        acc = Fv[i]
        for m in range(n):
            acc -= C[i, m] * ys[n + m] + K[i, m] * ys[m]
        work[i] = acc


@jit(inline="always")
def _derivatives(Minv, C, ys, Fv, n, rdof, work, pc, kk, row):  # pragma: no cover - compiled
    """Row ``row`` of the stage table: (v, M^-1 work, contact, viscous and forcing
    power, x[rdof]); ``pc`` is the power of the contact forces, W."""
    pv = 0.0
    pw = 0.0
    for i in range(n):
        vi = ys[n + i]
        acc = 0.0
        for m in range(n):
            acc += Minv[i, m] * work[m]
            pv += vi * C[i, m] * ys[n + m]
        kk[row, i] = vi
        kk[row, n + i] = acc
        pw += Fv[i] * vi
    kk[row, 2 * n] = pc
    kk[row, 2 * n + 1] = pv
    kk[row, 2 * n + 2] = pw
    kk[row, 2 * n + 3] = ys[rdof]


# --- after an evaluation -----------------------------------------------------------


@jit(inline="always")
def _state_changed(codes, code_c, ignore_separation):  # pragma: no cover - compiled
    """True when a contact's motion state differs from the committed one
    (optionally not counting separation, whose instants are grid points)."""
    changed = False
    for c in range(codes.shape[0]):
        if codes[c] != code_c[c]:
            if not ignore_separation or (codes[c] != SEPARATION and code_c[c] != SEPARATION):
                changed = True
    return changed


@jit(inline="always")
def _probe_done(changed, sm, blo, bhi, bit):  # pragma: no cover - compiled
    """One bisection step on the motion state; returns (blo, bhi, probes done,
    next evaluation): EVAL_PROBE to go on, EVAL_STAGE2 to redo the step up to
    the change (fraction bhi), EVAL_END when no split is needed (the probes
    overwrote the trial buffers: the end is evaluated again)."""
    if changed:
        bhi = sm
    else:
        blo = sm
    bit += 1
    # a change already at the first probe (just after the start: the first
    # step after a reversal out of macroslip) needs no split
    nxt = EVAL_END
    if bit < _BISECT_PROBES and not (changed and bit == 1):
        nxt = EVAL_PROBE
    elif bhi > _SPLIT_GUARD and bhi < 1.0 - _SPLIT_GUARD:
        nxt = EVAL_STAGE2
    return blo, bhi, bit, nxt


@jit(inline="always")
def _bisection(e, codes, code_c, sm, blo, bhi, bit, h, end_idx, attempt):  # pragma: no cover - compiled
    """Start the bisection for a change of motion state (after the end-of-step
    evaluation ``e = EVAL_END``) or take its next step (after a probe).

    Returns (blo, bhi, probes done, next evaluation, h, end index, attempt,
    located): the step is redone up to the change (h = bhi h, attempt 1) or,
    when no split is needed, its end is evaluated again and committed
    (located True).
    """
    if e == EVAL_END:
        return 0.0, 1.0, 0, EVAL_PROBE, h, end_idx, attempt, False
    blo, bhi, bit, nxt = _probe_done(_state_changed(codes, code_c, False), sm, blo, bhi, bit)
    if nxt == EVAL_STAGE2:
        h, end_idx, attempt = bhi * h, -1, 1
    return blo, bhi, bit, nxt, h, end_idx, attempt, nxt == EVAL_END


@jit(inline="always")
def _record(out_t, out_x, out_v, out_T, out_N, out_code, i, t, y, n, Tc, Nv, codes):  # pragma: no cover
    """Write sample ``i`` (time t, state y, contact forces, loads, codes)."""
    out_t[i] = t
    for k in range(n):
        out_x[i, k] = y[k]
        out_v[i, k] = y[n + k]
    for c in range(Tc.shape[0]):
        out_T[i, c] = Tc[c]
        out_N[i, c] = Nv[c]
        out_code[i, c] = codes[c]


@jit(inline="always")
def _record_step(out, nrec, t, y, n, Tc, Nv, codes, status):  # pragma: no cover - compiled
    """Record a committed step as sample ``nrec``; returns (samples, status).
    A full buffer is overwritten in its last row and the status says
    RUN_OVERFLOW (the caller repeats the run with a larger one)."""
    cap = out[0].shape[0]
    _record(out[0], out[1], out[2], out[3], out[4], out[5], min(nrec, cap - 1), t, y, n, Tc, Nv, codes)
    nrec += 1
    return nrec, RUN_OVERFLOW if nrec > cap and status == RUN_OK else status


@jit(inline="always")
def _extremum(y0, y1, h, rdof, n, xmax, xmin):  # pragma: no cover - compiled
    """(max, min) of x[rdof] so far, with the extremum inside the step (Hermite)."""
    xr0 = y0[rdof]
    xr1 = y1[rdof]
    vr0 = y0[n + rdof]
    vr1 = y1[n + rdof]
    if vr0 * vr1 < 0.0:
        sr = _hermite_root(xr0, xr1, vr0, vr1, h)
        xe = _hermite_value(xr0, xr1, vr0, vr1, h, sr)
        if xe > xmax:
            xmax = xe
        if xe < xmin:
            xmin = xe
    if xr1 > xmax:
        xmax = xr1
    if xr1 < xmin:
        xmin = xr1
    return xmax, xmin


@jit(inline="always")
def _commit(y0, y1, kk, code_c, codes, xcap, n, n_kind, nopen):  # pragma: no cover - compiled
    """Accept the step: y0 = y1, stage 1 of the next step, committed codes;
    returns (RUN_BLOWUP if the new state is non-finite or beyond the caps,
    else RUN_OK; ``nopen`` plus 1 if a spring contact is open at the end)."""
    status = RUN_OK
    opened = 0
    for c in range(codes.shape[0]):
        code_c[c] = codes[c]
        if n_kind[c] == NORMAL_SPRING and codes[c] == SEPARATION:
            opened = 1
    for r in range(y0.shape[0]):
        y0[r] = y1[r]
        kk[0, r] = kk[ROW_END, r]
    for i in range(2 * n):
        if not (abs(y0[i]) <= xcap[i]):
            status = RUN_BLOWUP
    return status, nopen + opened


@jit(inline="always")
def _period_summary(summ, zend, k, y0, n, xmax, xmin, nsteps, nopen, period):  # pragma: no cover - compiled
    """Summary row and end state of repetition k; resets the energy integrals."""
    summ[k, S_XMAX] = xmax
    summ[k, S_XMIN] = xmin
    summ[k, S_EC] = y0[2 * n]
    summ[k, S_EV] = y0[2 * n + 1]
    summ[k, S_W] = y0[2 * n + 2]
    summ[k, S_XMEAN] = y0[2 * n + 3] / period
    summ[k, S_STEPS] = nsteps
    summ[k, S_OPEN] = nopen
    for i in range(n):
        zend[k, i] = y0[i]
        zend[k, n + i] = y0[n + i]
    for r in range(2 * n, y0.shape[0]):
        y0[r] = 0.0


@jit(inline="always")
def _workspace(x, v, nc, m):  # pragma: no cover - compiled
    """Buffers of a run: y0 (start of the step, = (x, v, 0...); m pair
    energies after the four integrals), y1, ys (stage state), the stage
    table, forces and loads, trial and committed codes."""
    n = x.shape[0]
    y0 = np.zeros(2 * n + 4 + m)
    ys = np.zeros(2 * n + 4 + m)  # = y0: the state of the initial evaluation
    for i in range(n):
        y0[i] = ys[i] = x[i]
        y0[n + i] = ys[n + i] = v[i]
    return (y0, np.zeros(2 * n + 4 + m), ys, np.zeros((N_ROWS, 2 * n + 4 + m)), np.zeros(n),
            np.zeros(n), np.zeros(nc), np.zeros(nc), np.zeros(nc, dtype=np.int64), np.zeros(nc, dtype=np.int64))


@jit(inline="always")
def _after_start(y0, kk, code_c, codes, n, record, out, t0, Tc, Nv):  # pragma: no cover - compiled
    """After the initial evaluation (once per run): committed codes, stage 1,
    sample 0 (when recording), energy integrals zeroed; returns the samples recorded."""
    for c in range(codes.shape[0]):
        code_c[c] = codes[c]
    for r in range(y0.shape[0]):
        kk[0, r] = kk[ROW_END, r]
    nrec = 0
    if record:
        _record(out[0], out[1], out[2], out[3], out[4], out[5], 0, t0, y0, n, Tc, Nv, codes)
        nrec = 1
    for r in range(2 * n, y0.shape[0]):
        y0[r] = 0.0
    return nrec


@jit(inline="always")
def _write_back(x_io, v_io, S_io, y0, Sa, nc):  # pragma: no cover - compiled
    """Final state into the caller's x, v and law states (the nc contacts' rows; the pairs' sliders
    are written at every commit)."""
    n = x_io.shape[0]
    for i in range(n):
        x_io[i] = y0[i]
        v_io[i] = y0[n + i]
    for c in range(nc):
        for r in range(S_io.shape[1]):
            S_io[c, r] = Sa[c, r]


def _run_template(system, grid, control, io, out):  # pragma: no cover - compiled
    """March ``control[1]`` repetitions of the step grid (see module docstring).

    One piece, at the 100-line limit, on purpose: this is the innermost loop of
    every time-domain point, and its loop-carried scalars (the stage, the
    bisection bracket, the step and grid position) stay in registers only
    while they live in one function body. Split into named IR-inlined helpers
    returning those scalars as tuples (the stage point, the tabulated loads,
    the next step), the compiled march was 17 % slower per steady-state point
    on the paper damper (0.143 against 0.123 s for a 40-point sweep, best of
    5, alternated; the stage point's helper alone 13 %), so the helpers were
    folded back in.
    """
    Minv, K, C, (fsin, fcos), (tan_idx, tan_w, n_kind, n_par, n_idx, n_w, n_tab), P, (ipairs, ipar) = system
    tgrid, Ngrid, Fgrid, (sin_mid, sin_end, cos_mid, cos_end), N_mid = grid
    mode, nper, phase0, w, rdof, max_split, record, recontact = control
    x_io, v_io, S_io, xcap = io
    summ, zend = out[6], out[7]
    n, nc, J = x_io.shape[0], P.shape[0], tgrid.shape[0] - 1  # S_io: the contacts' rows, then the pairs' sliders
    Sa, Sb, pw, ia = S_io.copy(), S_io.copy(), _pair_workspace(S_io, nc, x_io, ipairs), 0
    y0, y1, ys, kk, work, Fv, Nv, Tc, codes, code_c = _workspace(x_io, v_io, nc, ipairs.shape[0])
    blo, bhi, bit, sm, located, e, ev_c, ev_n = 0.0, 1.0, 0, 0.0, False, EVAL_START, -1, 0.0
    nrec, status, done, k, j, attempt, nsplit, nsteps, nopen = 0, RUN_OK, 0, 0, 0, 0, 0, 0, 0
    tc, t_end, end_idx, h, period = tgrid[0], tgrid[1], 1, tgrid[1] - tgrid[0], tgrid[J] - tgrid[0]
    xmax = xmin = y0[rdof]
    while True:
        if e == EVAL_END:
            _rk4_combine(y0, kk, h, y1, ys)
            if attempt == 0 and nsplit < max_split:
                sbest = _reversal_fraction(tan_idx, tan_w, y0, y1, h, n)
                if SPRINGS:  # noqa: F821 - bound by specialize
                    sbest, ev_c, ev_n = _spring_split(n_kind, n_par, n_idx, n_w, y0, y1, h, n, recontact, sbest)
                if INTERFACES:  # noqa: F821 - bound by specialize
                    sbest, ev_c = _pair_split(ipairs, ipar, y0, y1, h, n, sbest, ev_c, pw)
                if sbest < 1.0:  # redo the step up to the velocity reversal or spring event
                    h, end_idx, attempt, e = sbest * h, -1, 1, EVAL_STAGE2
                    continue
        if e == EVAL_PROBE:
            sm = _SPLIT_GUARD if bit == 0 else 0.5 * (blo + bhi)
            tau, gidx = tc + sm * h, -1
            _probe_state(sm, h, y0, y1, ys, n)
        else:
            tau, gidx, a_ = _stage_time(e, tgrid[0], h, tc, end_idx)
            if e >= EVAL_STAGE2 and e < EVAL_END:  # RK stages (ys holds the start and the end already)
                for r in range(ys.shape[0]):
                    ys[r] = y0[r] + a_ * kk[e, r]
        fresh = mode == LOADS_HARMONIC and e >= EVAL_STAGE2 and e <= EVAL_END and attempt == 0 and nsplit == 0
        if mode == LOADS_HARMONIC:
            sp = (sin_mid[j] if e < EVAL_STAGE4 else sin_end[j]) if fresh else math.sin(phase0 + w * tau)
            for i in range(n):
                Fv[i] = fsin[i] * sp
            if PHASED:  # noqa: F821 - bound by specialize; F_i = f_i sin(w t + phi_i) = fsin_i sin(w t) + fcos_i cos(w t)
                _add_cosines(fcos, (cos_mid[j] if e < EVAL_STAGE4 else cos_end[j]) if fresh
                             else math.cos(phase0 + w * tau), Fv)  # fmt: skip
        else:
            _sampled_row(tgrid, Fgrid, tau, gidx, j, Fv)
        if gidx >= 0 or fresh:
            for c in range(nc):
                Nv[c] = Ngrid[gidx, c] if gidx >= 0 else N_mid[j, c]
        elif mode == LOADS_SAMPLED:
            _sampled_row(tgrid, Ngrid, tau, gidx, j, Nv)
        else:
            for c in range(nc):
                Nv[c] = PRESCRIBED_LOAD(n_kind[c], n_par, n_tab, c, phase0 + w * tau)  # noqa: F821 - bound by specialize
        _linear_forces(K, C, ys, Fv, n, work)  # right-hand side (law kernels here: in a helper 3.5x slower)
        if SPRINGS:  # noqa: F821 - bound by specialize; spring loads from the state, and their reactions
            _springs(n_kind, n_par, n_idx, n_w, ys, Nv, ev_c if e == EVAL_END else -1, ev_n, work)
        pc = 0.0
        row = e + 1 if (e >= EVAL_STAGE2 and e < EVAL_END) else (ROW_PROBE if e == EVAL_PROBE else ROW_END)
        if INTERFACES:  # noqa: F821 - the pairs' trial forces along the straight path from the committed point
            _pair_point(ipairs, ys, pw[1], pw[2])
            PAIR_STEP(ipar, pw[3], pw[4], pw[1], pw[2], pw[0][ia], pw[0][1 - ia], pw[5], pw[6], pw[7])  # noqa: F821
            pc += _pair_reactions(ipairs, ipar, ys, n, pw[5], pw[6], work, kk, row)
        for c in range(nc):
            u, du = tangential(tan_idx, tan_w, c, ys, 0), tangential(tan_idx, tan_w, c, ys, n)
            t_, k_, c_ = STEP(P[c], Sa[c], Sb[c], u, Nv[c])  # noqa: F821 - bound by specialize
            Tc[c], codes[c] = t_, c_
            apply_tangential_force(tan_idx, tan_w, c, t_, work)
            pc += t_ * du
        _derivatives(Minv, C, ys, Fv, n, rdof, work, pc, kk, row)
        if e < EVAL_END:  # the start, or RK stages 2, 3: on to the next stage (EVAL_START + 1 = EVAL_STAGE2)
            if e == EVAL_START:
                nrec = _after_start(y0, kk, code_c, codes, n, record, out, tgrid[0], Tc, Nv)
            e += 1
            continue
        # a contact's change of motion state inside an unsplit step: located by bisection
        if e == EVAL_PROBE or (attempt == 0 and nsplit < max_split and not located
                               and _state_changed(codes, code_c, True)):  # fmt: skip
            blo, bhi, bit, e, h, end_idx, attempt, located = _bisection(e, codes, code_c, sm, blo, bhi, bit, h, end_idx,
                                                                        attempt)  # fmt: skip
            continue
        located, Sa, Sb = False, Sb, Sa
        t_new = t_end if end_idx >= 0 else tc + h
        xmax, xmin = _extremum(y0, y1, h, rdof, n, xmax, xmin)
        status, nopen = _commit(y0, y1, kk, code_c, codes, xcap, n, n_kind, nopen)
        if INTERFACES:  # noqa: F821 - bound by specialize (with the repetition's pair summary at its end)
            ia, nopen = _pairs_commit(pw, ia, ipairs, y0, h, nopen, S_io, nc, out[8], k, n, end_idx == J, period)
        nsteps += 1
        if record:
            nrec, status = _record_step(out, nrec, k * period + t_new, y0, n, Tc, Nv, codes, status)
        if status != RUN_OK:
            break
        e, attempt, ev_c = EVAL_STAGE2, 0, -1  # next attempt: rest of the grid step, or the next grid step
        if end_idx < 0:
            nsplit, tc, h, end_idx = nsplit + 1, t_new, t_end - t_new, j + 1
            continue
        j, k, done, nsteps, nopen, xmax, xmin = _next_grid_step(summ, zend, j, J, k, done, y0, n, xmax, xmin, nsteps,
                                                                nopen, period, rdof)  # fmt: skip
        if k == nper:
            break
        nsplit, tc, t_end, end_idx, h = 0, tgrid[j], tgrid[j + 1], j + 1, tgrid[j + 1] - tgrid[j]
    _write_back(x_io, v_io, S_io, y0, Sa, nc)
    return nrec, status, done


@jit(inline="always")
def _next_grid_step(summ, zend, j, J, k, done, y0, n, xmax, xmin, nsteps, nopen, period, rdof):  # pragma: no cover
    """On to grid step j + 1; at the end of the grid, the summary of
    repetition k and a new repetition (grid step 0, counters and extrema
    reset). Returns (j, k, done, nsteps, nopen, xmax, xmin)."""
    j += 1
    if j == J:
        _period_summary(summ, zend, k, y0, n, xmax, xmin, nsteps, nopen, period)
        return 0, k + 1, done + 1, 0, 0, y0[rdof], y0[rdof]
    return j, k, done, nsteps, nopen, xmax, xmin


@jit
def grid_trig(tgrid, w, phase0):  # pragma: no cover - compiled
    """Forcing sines and cosines at the midpoint and end of every step of a
    harmonic grid (the grid repeats each period, so an unsplit step reuses
    them): ``(sin_mid, sin_end, cos_mid, cos_end)``."""
    J = tgrid.shape[0] - 1
    sin_mid = np.empty(J)
    sin_end = np.empty(J)
    cos_mid = np.empty(J)
    cos_end = np.empty(J)
    for j in range(J):
        am = phase0 + w * (tgrid[j] + 0.5 * (tgrid[j + 1] - tgrid[j]))
        ae = phase0 + w * tgrid[j + 1]
        sin_mid[j] = math.sin(am)
        sin_end[j] = math.sin(ae)
        cos_mid[j] = math.cos(am)
        cos_end[j] = math.cos(ae)
    return sin_mid, sin_end, cos_mid, cos_end


def compiled_runner(step, springs: bool = False, phased: bool = False, interfaces: bool = False):
    """The RK4 runner with ``step`` (a law kernel or a mixed-law dispatcher)
    bound, compiled and cached; ``springs`` (a contact has a normal spring),
    ``phased`` (a forcing phase is not 0) and ``interfaces`` (the system has
    interface pairs) are compile-time constants, so that systems without
    them compile none of that work. The pairs' kernel is bound as
    ``PAIR_STEP`` so that the runner's cache name follows its source."""
    from .._jit import specialize
    from ..interfaces import interface_step

    return specialize(_run_template, STEP=step, PRESCRIBED_LOAD=prescribed_load, SPRINGS=bool(springs),
                      PHASED=bool(phased), INTERFACES=bool(interfaces), PAIR_STEP=interface_step)  # fmt: skip


__all__ = [
    "S_XMAX", "S_XMIN", "S_EC", "S_EV", "S_W", "S_XMEAN", "S_STEPS", "S_OPEN", "N_SUMMARY",
    "RUN_OK", "RUN_BLOWUP", "RUN_OVERFLOW", "LOADS_HARMONIC", "LOADS_SAMPLED",
    "compiled_runner", "grid_trig",
]  # fmt: skip
