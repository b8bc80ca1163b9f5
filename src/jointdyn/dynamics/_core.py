"""Compiled time-stepping core (templates specialised per contact law).

Scheme: classical explicit Runge-Kutta (RK4) on ``y = (x, v, E_c, E_v, W, I_x)``
with the contact forces evaluated at every stage as a *trial step* of the
law from the committed state (kernel contract, laws/_base.py). At the end of
an accepted step the law is evaluated once more at the end displacement and
that trial is committed (buffer swap); the same evaluation gives the first
stage of the next step (first-same-as-last).

Events are never smeared over a step:

* step boundaries are put exactly at the zero crossings of every N_c(t)
  (the grid passed in contains them, with N snapped to exactly 0 at a
  separation and to a tiny positive value at a re-contact, so that the
  committed law state is "separated" resp. "virgin at the re-contact point");
* when the relative velocity of any contact changes sign inside a step, the
  instant of the extremum of u is located on the cubic Hermite interpolant
  of (u, du) over the step, the step is redone up to that instant and
  committed there, so that the law's reversal point is the true extremum.

The templates call the global placeholder ``STEP`` (the law kernel) and are
compiled per law with :func:`jointdyn._jit.specialize`.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import jit

# columns of the per-period summary
S_XMAX, S_XMIN, S_EC, S_EV, S_W, S_XMEAN, S_STEPS = range(7)
N_SUMMARY = 7

# run status
RUN_OK, RUN_BLOWUP, RUN_OVERFLOW = 0, 1, 2

# a change of motion state inside a step is located by this many probes (the
# first at _SPLIT_GUARD, then bisection: 2^-38 of a step) and the step is
# split there unless it lies within _SPLIT_GUARD of either end; compile-time
# constants of the templates (a change here recompiles via the source hash).
# Fewer probes (24: 1e-7 of a step) changed the outcome of a nearly
# unstable orbit (eta 1.5, beta 2, gamma 1.18: periodic -> not settled)
_BISECT_PROBES = 40
_SPLIT_GUARD = 1e-6


@jit
def _hermite_root(u0, u1, du0, du1, h):
    """Root s in (0, 1) of the derivative of the cubic Hermite interpolant.

    ``du0`` and ``du1`` (velocities, units of u per second) have opposite
    signs, so the derivative has exactly one root in (0, 1); found by
    bisection on the quadratic (robust, called only at reversals).
    """
    d = (u1 - u0) / h
    lo = 0.0
    hi = 1.0
    sg0 = du0 > 0.0
    for _ in range(60):
        s = 0.5 * (lo + hi)
        p = du0 * (1.0 - 4.0 * s + 3.0 * s * s) + du1 * (3.0 * s * s - 2.0 * s) + 6.0 * d * (s - s * s)
        if (p > 0.0) == sg0:
            lo = s
        else:
            hi = s
    return 0.5 * (lo + hi)


@jit
def _hermite_value(u0, u1, du0, du1, h, s):
    """Cubic Hermite interpolant of u at fraction s of a step of length h."""
    s2 = s * s
    s3 = s2 * s
    return (
        (2.0 * s3 - 3.0 * s2 + 1.0) * u0
        + (s3 - 2.0 * s2 + s) * h * du0
        + (-2.0 * s3 + 3.0 * s2) * u1
        + (s3 - s2) * h * du1
    )


def _run_template(
    mode, tgrid, Ngrid, Fgrid, nper, phase0, w, fvec, n0, n1, dlt,
    Minv, K, C, cdof, cdof2, P, S_io, x_io, v_io, rdof, xcap, max_split,
    rec, out_t, out_x, out_v, out_T, out_N, out_code, summ, zend,
    sin_mid, sin_end, N_mid,
):  # pragma: no cover - compiled
    """March ``nper`` repetitions of the step grid ``tgrid`` (see module docstring).

    Returns (samples recorded, status, periods completed). ``x_io``, ``v_io``
    and ``S_io`` (committed law states, one row per contact) are updated in
    place. ``summ[k]`` holds the per-period summary (max/min/mean of
    x[rdof], contact and viscous dissipation, work of the forcing, steps)
    and ``zend[k]`` the state (x, v) at the end of repetition k.

    The right-hand side (law trial steps included) is evaluated at one
    single place in the loop body, so that it is compiled inline (a call
    per evaluation with a dozen array arguments costs more than the law).
    """
    n = x_io.shape[0]
    nc = cdof.shape[0]
    J = tgrid.shape[0] - 1
    ny = 2 * n + 4
    period = tgrid[J] - tgrid[0]
    Sa = S_io.copy()
    Sb = S_io.copy()
    y0 = np.zeros(ny)
    y1 = np.zeros(ny)
    ys = np.zeros(ny)
    kk = np.zeros((6, ny))  # rows 1..3: stages 2..4; row 4: end of step (= next row 0); row 5: probes
    work = np.zeros(n)
    Fv = np.zeros(n)
    Nv = np.zeros(nc)
    Tc = np.zeros(nc)
    codes = np.zeros(nc, dtype=np.int64)
    code_c = np.zeros(nc, dtype=np.int64)  # motion state of the committed laws
    # bisection for a change of motion state inside a step (e == 4 probes)
    blo = 0.0
    bhi = 1.0
    bit = 0
    sm = 0.0
    located = False
    for i in range(n):
        y0[i] = x_io[i]
        y0[n + i] = v_io[i]
    # mode 0: sin_mid, sin_end, N_mid (see grid_sines) are the harmonic loads
    # at the midpoint and the end of every grid step, computed once per grid
    nrec = 0
    cap = out_t.shape[0]
    status = 0
    done = 0
    # evaluation state machine: e = 0, 1, 2 are the RK stages 2..4 of the
    # current attempt, e = 3 the end of the step (commit), e = 4 a probe of
    # the bisection for a change of motion state inside the step; e = -1
    # the initial evaluation at the start.
    k = 0
    j = 0
    tc = tgrid[0]
    t_end = tgrid[1]
    h = t_end - tc
    end_idx = 1
    attempt = 0
    nsplit = 0
    nsteps = 0
    xmax = y0[rdof]
    xmin = y0[rdof]
    e = -1
    while True:
        # ---- where to evaluate ------------------------------------------
        if e == -1:
            tau = tgrid[0]
            gidx = 0
            for r in range(ny):
                ys[r] = y0[r]
        elif e < 3:
            a_ = 0.5 * h if e < 2 else h
            for r in range(ny):
                ys[r] = y0[r] + a_ * kk[e, r]
            tau = tc + a_
            gidx = end_idx if e == 2 else -1
        elif e == 4:
            # probe at fraction sm of the step on the cubic Hermite
            # interpolant of the step (only the contact states are used)
            # first probe just after the start: a change right there (the
            # first step after a reversal out of macroslip) needs no split
            sm = _SPLIT_GUARD if bit == 0 else 0.5 * (blo + bhi)
            for i in range(n):
                ys[i] = _hermite_value(y0[i], y1[i], y0[n + i], y1[n + i], h, sm)
                ys[n + i] = y0[n + i] + sm * (y1[n + i] - y0[n + i])
            tau = tc + sm * h
            gidx = -1
        else:
            for r in range(ny):
                y1[r] = y0[r] + h / 6.0 * (kk[0, r] + 2.0 * kk[1, r] + 2.0 * kk[2, r] + kk[3, r])
            if attempt == 0 and nsplit < max_split:
                # velocity reversal of any contact inside the step?
                sbest = 2.0
                for c in range(nc):
                    d1 = cdof[c]
                    d2 = cdof2[c]
                    du0 = y0[n + d1]
                    du1 = y1[n + d1]
                    u0 = y0[d1]
                    u1 = y1[d1]
                    if d2 >= 0:
                        du0 -= y0[n + d2]
                        du1 -= y1[n + d2]
                        u0 -= y0[d2]
                        u1 -= y1[d2]
                    if du0 * du1 < 0.0:
                        sr = _hermite_root(u0, u1, du0, du1, h)
                        if sr > 1e-6 and sr < 1.0 - 1e-6 and sr < sbest:
                            sbest = sr
                if sbest < 1.0:
                    h = sbest * h
                    end_idx = -1
                    attempt = 1
                    e = 0
                    continue
            for r in range(ny):
                ys[r] = y1[r]
            tau = tc + h
            gidx = end_idx
        # ---- loads at tau (grid value at a grid point) --------------------
        if mode == 0:
            # an unsplit grid step (attempt 0, no split yet) evaluates at its
            # midpoint (stages 2, 3) and its end (stage 4, commit)
            fresh = e >= 0 and e <= 3 and attempt == 0 and nsplit == 0
            if fresh:
                sp = sin_mid[j] if e < 2 else sin_end[j]
            else:
                ph = phase0 + w * tau
                sp = math.sin(ph)
            for i in range(n):
                Fv[i] = fvec[i] * sp
            if gidx >= 0:
                for c in range(nc):
                    Nv[c] = Ngrid[gidx, c]
            elif fresh:
                for c in range(nc):
                    Nv[c] = N_mid[j, c]
            else:
                for c in range(nc):
                    Nv[c] = n0[c] + n1[c] * math.sin(phase0 + w * tau + dlt[c])
        else:
            if gidx >= 0:
                for i in range(n):
                    Fv[i] = Fgrid[gidx, i]
                for c in range(nc):
                    Nv[c] = Ngrid[gidx, c]
            else:
                al = (tau - tgrid[j]) / (tgrid[j + 1] - tgrid[j])
                for i in range(n):
                    Fv[i] = Fgrid[j, i] + al * (Fgrid[j + 1, i] - Fgrid[j, i])
                for c in range(nc):
                    Nv[c] = Ngrid[j, c] + al * (Ngrid[j + 1, c] - Ngrid[j, c])
        # ---- right-hand side: M x'' = F - C v - K x - sum_c B_c T_c ---------
        row = e + 1 if (e >= 0 and e < 3) else (5 if e == 4 else 4)
        for i in range(n):
            acc = Fv[i]
            for m in range(n):
                acc -= C[i, m] * ys[n + m] + K[i, m] * ys[m]
            work[i] = acc
        pc = 0.0
        for c in range(nc):
            d1 = cdof[c]
            d2 = cdof2[c]
            u = ys[d1]
            du = ys[n + d1]
            if d2 >= 0:
                u -= ys[d2]
                du -= ys[n + d2]
            t_, k_, c_ = STEP(P[c], Sa[c], Sb[c], u, Nv[c])  # noqa: F821 - bound by specialize
            Tc[c] = t_
            codes[c] = c_
            work[d1] -= t_
            if d2 >= 0:
                work[d2] += t_
            pc += t_ * du
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
        # ---- after the evaluation -----------------------------------------
        if e == -1:
            for c in range(nc):
                code_c[c] = codes[c]
            for r in range(ny):
                kk[0, r] = kk[4, r]
            if rec:
                out_t[0] = tgrid[0]
                for i in range(n):
                    out_x[0, i] = y0[i]
                    out_v[0, i] = y0[n + i]
                for c in range(nc):
                    out_T[0, c] = Tc[c]
                    out_N[0, c] = Nv[c]
                    out_code[0, c] = codes[c]
                nrec = 1
            for r in range(2 * n, ny):
                y0[r] = 0.0
            e = 0
            continue
        if e < 3:
            e += 1
            continue
        if e == 4:
            changed = False
            for c in range(nc):
                if codes[c] != code_c[c]:
                    changed = True
            if changed:
                bhi = sm
            else:
                blo = sm
            bit += 1
            if bit < _BISECT_PROBES and not (changed and bit == 1):
                continue
            if bhi > _SPLIT_GUARD and bhi < 1.0 - _SPLIT_GUARD:
                # redo the step up to the change of state
                h = bhi * h
                end_idx = -1
                attempt = 1
                e = 0
                continue
            # no split after all: the probes overwrote the trial buffers,
            # evaluate the end of the step again and commit it
            located = True
            e = 3
            continue
        # change of motion state (e.g. onset or end of macroslip) inside the
        # step: locate it by bisection on the law's state code (trial steps
        # from the committed state) and redo the step up to there, so that
        # kinks of the force are not smeared over a step (separation and
        # re-contact are already grid points)
        if attempt == 0 and nsplit < max_split and not located:
            changed = False
            for c in range(nc):
                if codes[c] != code_c[c] and codes[c] != 2 and code_c[c] != 2:
                    changed = True
            if changed:
                blo = 0.0
                bhi = 1.0
                bit = 0
                e = 4
                continue
        located = False
        # commit the step: swap the law-state buffers
        Sa, Sb = Sb, Sa
        for c in range(nc):
            code_c[c] = codes[c]
        t_new = t_end if end_idx >= 0 else tc + h
        # extremum of the response DOF inside the step (Hermite)
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
        for r in range(ny):
            y0[r] = y1[r]
            kk[0, r] = kk[4, r]
        nsteps += 1
        if rec:
            if nrec >= cap:
                status = 2
            else:
                out_t[nrec] = k * period + t_new
                for i in range(n):
                    out_x[nrec, i] = y0[i]
                    out_v[nrec, i] = y0[n + i]
                for c in range(nc):
                    out_T[nrec, c] = Tc[c]
                    out_N[nrec, c] = Nv[c]
                    out_code[nrec, c] = codes[c]
                nrec += 1
        for i in range(2 * n):
            if not (abs(y0[i]) <= xcap[i]):
                status = 1
        if status != 0:
            break
        # next attempt: rest of the grid step, or the next grid step
        e = 0
        attempt = 0
        if end_idx < 0:
            nsplit += 1
            tc = t_new
            h = t_end - tc
            end_idx = j + 1
            continue
        j += 1
        if j == J:
            summ[k, 0] = xmax
            summ[k, 1] = xmin
            summ[k, 2] = y0[2 * n]
            summ[k, 3] = y0[2 * n + 1]
            summ[k, 4] = y0[2 * n + 2]
            summ[k, 5] = y0[2 * n + 3] / period
            summ[k, 6] = nsteps
            for i in range(n):
                zend[k, i] = y0[i]
                zend[k, n + i] = y0[n + i]
            done += 1
            k += 1
            if k == nper:
                break
            j = 0
            xmax = y0[rdof]
            xmin = y0[rdof]
            nsteps = 0
            for r in range(2 * n, ny):
                y0[r] = 0.0
        nsplit = 0
        tc = tgrid[j]
        t_end = tgrid[j + 1]
        h = t_end - tc
        end_idx = j + 1
    for i in range(n):
        x_io[i] = y0[i]
        v_io[i] = y0[n + i]
    for c in range(nc):
        for r in range(S_io.shape[1]):
            S_io[c, r] = Sa[c, r]
    return nrec, status, done


@jit
def grid_sines(tgrid, w, phase0, n0, n1, dlt):
    """Forcing sines at the midpoint and end of every step of a harmonic grid
    and the normal loads at the midpoints (the grid repeats each period, so an
    unsplit step reuses them; arguments ``sin_mid, sin_end, N_mid`` of the
    runner in mode 0)."""
    J = tgrid.shape[0] - 1
    nc = n0.shape[0]
    sin_mid = np.empty(J)
    sin_end = np.empty(J)
    N_mid = np.empty((J, nc))
    for j in range(J):
        pm = phase0 + w * (tgrid[j] + 0.5 * (tgrid[j + 1] - tgrid[j]))
        sin_mid[j] = math.sin(pm)
        sin_end[j] = math.sin(phase0 + w * tgrid[j + 1])
        for c in range(nc):
            N_mid[j, c] = n0[c] + n1[c] * math.sin(pm + dlt[c])
    return sin_mid, sin_end, N_mid


@jit
def grid_loads(tgrid, w, n0, n1, dlt):
    """Normal loads N_c(t) = n0_c + n1_c sin(w t + delta_c) at the grid points, N."""
    N = np.empty((tgrid.shape[0], n0.shape[0]))
    for j in range(tgrid.shape[0]):
        for c in range(n0.shape[0]):
            N[j, c] = n0[c] + n1[c] * math.sin(w * tgrid[j] + dlt[c])
    return N


def compiled_runner(step):
    """The RK4 runner with ``step`` (a law kernel) bound, compiled and cached."""
    from .._jit import specialize

    return specialize(_run_template, STEP=step)
