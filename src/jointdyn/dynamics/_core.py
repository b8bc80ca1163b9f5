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


@jit
def _loads(mode, tau, j, end_of_step, tgrid, Ngrid, Fgrid, phase0, w, fvec, n0, n1, dlt, Fv, Nv):
    """Forcing F(t) (per DOF) and normal loads N_c(t) at local time ``tau``.

    mode 0 (harmonic): F = f sin(phase0 + w tau), N = n0 + n1 sin(phase0 + w tau + delta);
    at a grid point (``end_of_step`` = grid index or -1) N is the grid value
    (exactly 0 / tiny positive at separation / re-contact).
    mode 1 (sampled): linear interpolation inside grid step ``j``.
    """
    n = Fv.shape[0]
    nc = Nv.shape[0]
    if mode == 0:
        ph = phase0 + w * tau
        sp = math.sin(ph)
        for i in range(n):
            Fv[i] = fvec[i] * sp
        if end_of_step >= 0:
            for c in range(nc):
                Nv[c] = Ngrid[end_of_step, c]
        else:
            for c in range(nc):
                Nv[c] = n0[c] + n1[c] * math.sin(ph + dlt[c])
    else:
        if end_of_step >= 0:
            for i in range(n):
                Fv[i] = Fgrid[end_of_step, i]
            for c in range(nc):
                Nv[c] = Ngrid[end_of_step, c]
        else:
            a = (tau - tgrid[j]) / (tgrid[j + 1] - tgrid[j])
            for i in range(n):
                Fv[i] = Fgrid[j, i] + a * (Fgrid[j + 1, i] - Fgrid[j, i])
            for c in range(nc):
                Nv[c] = Ngrid[j, c] + a * (Ngrid[j + 1, c] - Ngrid[j, c])


def _accel_template(y, Fv, Nv, Minv, K, C, cdof, cdof2, P, Sa, Sb, rdof, kout, Tc, codes, work):  # pragma: no cover
    """Time derivative of y = (x, v, E_c, E_v, W, I_x) with trial contact forces.

    M x'' = F - C v - K x - sum_c B_c T_c(u_c, N_c), u_c = x[dof] - x[dof2];
    E_c' = sum_c T_c u_c' (dissipated by contacts), E_v' = v.C v, W' = F.v,
    I_x' = x[rdof]. Trial states are written to ``Sb`` (``Sa`` is committed).
    """
    n = Fv.shape[0]
    nc = Nv.shape[0]
    for i in range(n):
        acc = Fv[i]
        for m in range(n):
            acc -= C[i, m] * y[n + m] + K[i, m] * y[m]
        work[i] = acc
    pc = 0.0
    for c in range(nc):
        d1 = cdof[c]
        d2 = cdof2[c]
        u = y[d1]
        du = y[n + d1]
        if d2 >= 0:
            u -= y[d2]
            du -= y[n + d2]
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
        vi = y[n + i]
        s = 0.0
        for m in range(n):
            s += Minv[i, m] * work[m]
            pv += vi * C[i, m] * y[n + m]
        kout[i] = vi
        kout[n + i] = s
        pw += Fv[i] * vi
    kout[2 * n] = pc
    kout[2 * n + 1] = pv
    kout[2 * n + 2] = pw
    kout[2 * n + 3] = y[rdof]


def _run_template(
    mode, tgrid, Ngrid, Fgrid, nper, phase0, w, fvec, n0, n1, dlt,
    Minv, K, C, cdof, cdof2, P, S_io, x_io, v_io, rdof, xcap, max_split,
    rec, out_t, out_x, out_v, out_T, out_N, out_code, summ, zend,
):  # pragma: no cover - compiled
    """March ``nper`` repetitions of the step grid ``tgrid`` (see module docstring).

    Returns (samples recorded, status, periods completed). ``x_io``, ``v_io``
    and ``S_io`` (committed law states, one row per contact) are updated in
    place. ``summ[k]`` holds the per-period summary (max/min/mean of
    x[rdof], contact and viscous dissipation, work of the forcing, steps)
    and ``zend[k]`` the state (x, v) at the end of repetition k.
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
    kk = np.zeros((4, ny))
    kend = np.zeros(ny)
    work = np.zeros(n)
    Fv = np.zeros(n)
    Nv = np.zeros(nc)
    Tc = np.zeros(nc)
    codes = np.zeros(nc, dtype=np.int64)
    for i in range(n):
        y0[i] = x_io[i]
        y0[n + i] = v_io[i]
    _loads(mode, tgrid[0], 0, 0, tgrid, Ngrid, Fgrid, phase0, w, fvec, n0, n1, dlt, Fv, Nv)
    ACCEL(y0, Fv, Nv, Minv, K, C, cdof, cdof2, P, Sa, Sb, rdof, kend, Tc, codes, work)  # noqa: F821
    nrec = 0
    cap = out_t.shape[0]
    status = 0
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
    done = 0
    for k in range(nper):
        toff = k * period
        xmax = y0[rdof]
        xmin = y0[rdof]
        for r in range(2 * n, ny):
            y0[r] = 0.0
        nsteps = 0
        for j in range(J):
            tc = tgrid[j]
            t_end = tgrid[j + 1]
            nsplit = 0
            while True:
                h = t_end - tc
                end_idx = j + 1
                for attempt in range(2):
                    for r in range(ny):
                        kk[0, r] = kend[r]
                    for st in range(3):
                        a_ = 0.5 * h if st < 2 else h
                        for r in range(ny):
                            ys[r] = y0[r] + a_ * kk[st, r]
                        if st < 2:
                            _loads(mode, tc + 0.5 * h, j, -1, tgrid, Ngrid, Fgrid, phase0, w, fvec, n0, n1, dlt, Fv, Nv)
                        else:
                            _loads(mode, tc + h, j, end_idx, tgrid, Ngrid, Fgrid, phase0, w, fvec, n0, n1, dlt, Fv, Nv)
                        ACCEL(ys, Fv, Nv, Minv, K, C, cdof, cdof2, P, Sa, Sb, rdof, kk[st + 1], Tc, codes, work)  # noqa: F821
                    for r in range(ny):
                        y1[r] = y0[r] + h / 6.0 * (kk[0, r] + 2.0 * kk[1, r] + 2.0 * kk[2, r] + kk[3, r])
                    if attempt == 1 or nsplit >= max_split:
                        break
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
                            s = _hermite_root(u0, u1, du0, du1, h)
                            if s > 1e-6 and s < 1.0 - 1e-6 and s < sbest:
                                sbest = s
                    if sbest < 1.0:
                        h = sbest * h
                        end_idx = -1
                    else:
                        break
                # commit: evaluate at the end of the step, swap buffers
                t_new = tc + h
                if end_idx < 0:
                    _loads(mode, t_new, j, -1, tgrid, Ngrid, Fgrid, phase0, w, fvec, n0, n1, dlt, Fv, Nv)
                else:
                    _loads(mode, t_new, j, end_idx, tgrid, Ngrid, Fgrid, phase0, w, fvec, n0, n1, dlt, Fv, Nv)
                    t_new = t_end
                ACCEL(y1, Fv, Nv, Minv, K, C, cdof, cdof2, P, Sa, Sb, rdof, kend, Tc, codes, work)  # noqa: F821
                Sa, Sb = Sb, Sa
                # extremum of the response DOF inside the step (Hermite)
                xr0 = y0[rdof]
                xr1 = y1[rdof]
                vr0 = y0[n + rdof]
                vr1 = y1[n + rdof]
                if vr0 * vr1 < 0.0:
                    s = _hermite_root(xr0, xr1, vr0, vr1, h)
                    xe = _hermite_value(xr0, xr1, vr0, vr1, h, s)
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
                nsteps += 1
                if rec:
                    if nrec >= cap:
                        status = 2
                    else:
                        out_t[nrec] = toff + t_new
                        for i in range(n):
                            out_x[nrec, i] = y0[i]
                            out_v[nrec, i] = y0[n + i]
                        for c in range(nc):
                            out_T[nrec, c] = Tc[c]
                            out_N[nrec, c] = Nv[c]
                            out_code[nrec, c] = codes[c]
                        nrec += 1
                bad = False
                for i in range(2 * n):
                    if not (abs(y0[i]) <= xcap[i]):
                        bad = True
                if bad:
                    status = 1
                tc = t_new
                if end_idx >= 0 or status != 0:
                    break
                nsplit += 1
            if status != 0:
                break
        if status != 0:
            break
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
    for i in range(n):
        x_io[i] = y0[i]
        v_io[i] = y0[n + i]
    for c in range(nc):
        for r in range(S_io.shape[1]):
            S_io[c, r] = Sa[c, r]
    return nrec, status, done


def compiled_runner(step):
    """The RK4 runner with ``step`` (a law kernel) bound, compiled and cached."""
    from .._jit import specialize

    accel = specialize(_accel_template, STEP=step)
    return specialize(_run_template, STEP=step, ACCEL=accel)
