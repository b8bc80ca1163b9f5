"""Forced response near a resonance from one nonlinear mode (single-nonlinear-mode synthesis).

Krack, Panning-von Scheidt and Wallaschek (2013, 2014): near the resonance
of a well-separated mode the forced response is assumed to be that mode at
its own amplitude, driven at the forcing frequency Omega. Projecting the
equation of motion on the first harmonic of the mode gives, per backbone
point (omega, xi, complex first-harmonic mode shape psi = a1 - i b1)::

    (omega^2 - Omega^2 + i Omega xi) q = phi^H F,   phi = psi / q,   q = sqrt(psi^H M psi),

with F the complex amplitudes of the forcing f_j sin(Omega t + phi_j)
(``F_j = -i f_j exp(i phi_j)``). With ``r = |phi^H F| / q`` (1/s^2) its
modulus is ``(omega^2 - Omega^2)^2 + xi^2 Omega^2 = r^2``, a quadratic in
``Omega^2`` with the roots::

    Omega^2 = omega^2 - xi^2 / 2 -+ sqrt(r^2 - xi^2 (omega^2 - xi^2 / 4)),

the two flanks of the response curve at that amplitude. The response of
the output DOF is then the backbone's amplitude itself. The flanks meet at
the peak, where ``g = r^2 - xi^2 (omega^2 - xi^2 / 4)`` changes sign, at
``Omega^2 = omega^2 - xi^2 / 2``; it is located between two backbone
points to ``peak_rtol`` (a keyword of :func:`single_mode_frc`) in amplitude, by solving the EPMC
at intermediate amplitudes (the QSMA backbone is interpolated instead).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _validate as V
from ..systems import System
from .backbone import Backbone, ModeStatus

__all__ = ["single_mode_frc", "modal_forcing"]

def _forcing_vector(system: System) -> np.ndarray:
    """Complex amplitudes F_j = -i f_j exp(i phi_j) of the forcing f_j sin(Omega t + phi_j), N."""
    return -1j * system.force * np.exp(1j * np.radians(system.force_phase_deg))


def modal_forcing(backbone: Backbone, system: System | None = None) -> np.ndarray:
    """``r = |psi^H F| / q^2`` per backbone point (1/s^2): the forcing projected on the nonlinear mode."""
    system = backbone.system if system is None else system
    n = system.ndof
    X = backbone.X.reshape(-1, 2 * backbone.harmonics + 1, n)
    psi = X[:, 1] - 1j * X[:, 2]
    F = _forcing_vector(system)
    return np.abs(psi.conj() @ F) / backbone.modal_amplitude ** 2


def _gap(r, w, xi):
    """g = r^2 - xi^2 (omega^2 - xi^2 / 4): >= 0 where the amplitude is reached at some frequency."""
    return r * r - xi * xi * (w * w - 0.25 * xi * xi)


def _flanks(r, w, xi):
    """(Omega_low, Omega_high) in rad/s (NaN where not reached)."""
    g = _gap(r, w, xi)
    mid = w * w - 0.5 * xi * xi
    root = np.sqrt(np.where(g >= 0.0, g, np.nan))
    lo = mid - root
    return np.sqrt(np.where(lo > 0.0, lo, np.nan)), np.sqrt(mid + root)


def _refine(backbone: Backbone, system: System, i: int, rtol: float):
    """(amplitude m, omega rad/s, xi 1/s) of the peak between backbone points i and i + 1, located to
    ``rtol`` in amplitude (relative)."""
    from scipy.optimize import brentq

    b = backbone
    lam = np.log10(b.amplitude_m[i:i + 2])
    problem = b.problem
    if problem is None:  # QSMA: linear interpolation of g, omega and xi in log amplitude
        r = modal_forcing(b, system)[i:i + 2]
        g = _gap(r, b.omega_rad_s[i:i + 2], b.xi_rad_s[i:i + 2])
        t = g[0] / (g[0] - g[1])
        w, xi = (float(v[i] + t * (v[i + 1] - v[i])) for v in (b.omega_rad_s, b.xi_rad_s))
        return 10.0 ** (lam[0] + t * (lam[1] - lam[0])), w, xi
    V = [problem.pack(b.X[k], b.omega_rad_s[k], b.xi_rad_s[k]) for k in (i, i + 1)]
    F = _forcing_vector(system)
    found = {}

    def g_at(lm):
        t = (lm - lam[0]) / (lam[1] - lam[0])
        v, ok, _ = problem.solve(10.0 ** lm, V[0] + t * (V[1] - V[0]))
        if not ok:
            raise ArithmeticError
        X, w, xi = problem.unpack(v, lm)
        Xm = X.reshape(-1, problem.n)
        psi = Xm[1] - 1j * Xm[2]
        q2 = problem.modal_amplitude(X) ** 2
        found[lm] = (w, xi)
        return float(_gap(abs(psi.conj() @ F) / q2, w, xi))

    try:
        lm = brentq(g_at, lam[0], lam[1], xtol=rtol / math.log(10.0))
        if lm not in found:
            g_at(lm)
    except ArithmeticError:  # Newton failed between the points: interpolate instead
        return _refine(dataclasses.replace(b, problem=None), system, i, rtol)
    return (10.0 ** lm, *found[lm])


def single_mode_frc(backbone: Backbone, system: System | None = None, *, refine: bool = True,
                    peak_rtol: float = 1e-10):  # fmt: skip
    """Forced response curve near the backbone's resonance from the single nonlinear mode (module docstring).

    Parameters
    ----------
    backbone : Backbone
        From :func:`~jointdyn.modes.epmc` (or :func:`~jointdyn.modes.qsma`).
    system : System, optional
        Forced system: its ``force`` (N) and ``force_phase_deg`` give the
        forcing f_j sin(Omega t + phi_j); the structure must be the
        backbone's (default: the backbone's own system and forcing).
    refine : bool
        Locate the peak between backbone points (else: the last backbone
        point below it).
    peak_rtol : float
        Relative tolerance in amplitude to which ``refine`` locates the peak between two EPMC backbone
        points, each try an EPMC solve (default 1e-10; in (0, 1)).

    Returns
    -------
    xarray.Dataset
        Dim ``point``, the curve from the low-frequency flank through the
        peak down the high-frequency flank: ``omega_rad_s`` (forcing
        frequency), ``gamma`` (omega / w0), ``amplitude_m`` (first-harmonic
        amplitude of the output DOF), ``flank`` (-1 low, 0 peak, 1 high),
        ``modal_forcing`` (r, 1/s^2); attrs ``status`` (complete,
        peak-above-range, peak-below-range), ``message``,
        ``peak_amplitude_m``, ``peak_omega_rad_s``, ``peak_gamma`` (NaN
        without a peak), ``backbone_method``.
    """
    import xarray as xr

    if not isinstance(backbone, Backbone):
        raise ValueError("backbone must be a jointdyn.modes.Backbone (from epmc or qsma)")
    system = backbone.system if system is None else system
    if not isinstance(system, System) or system.ndof != backbone.system.ndof:
        raise ValueError(f"system must be a jointdyn.System with the backbone's {backbone.system.ndof} DOFs")
    if not np.any(system.force != 0.0):
        raise ValueError("system.force must have a non-zero entry: the synthesis needs a forcing")
    peak_rtol = V.in_range("peak_rtol", peak_rtol, 0.0, 1.0, lo_open=True, hi_open=True)
    b = backbone
    r = modal_forcing(b, system)
    g = _gap(r, b.omega_rad_s, b.xi_rad_s)
    above = np.flatnonzero(g < 0.0)
    if b.points == 0 or (above.size and above[0] == 0):
        status, end = ModeStatus.PEAK_BELOW_RANGE, 0
    elif above.size == 0:
        status, end = ModeStatus.PEAK_ABOVE_RANGE, b.points
    else:
        status, end = ModeStatus.COMPLETE, int(above[0])
    lo, hi = _flanks(r[:end], b.omega_rad_s[:end], b.xi_rad_s[:end])
    amp = b.amplitude_m[:end]
    peak = (math.nan, math.nan)
    mid = ([], [], [])
    if status is ModeStatus.COMPLETE:
        if refine:
            a_p, w_p, xi_p = _refine(b, system, end - 1, peak_rtol)
        else:
            a_p, w_p, xi_p = amp[-1], b.omega_rad_s[end - 1], b.xi_rad_s[end - 1]
        peak = (a_p, math.sqrt(w_p * w_p - 0.5 * xi_p * xi_p))
        mid = ([peak[1]], [a_p], [0])
    keep = np.isfinite(lo)
    omega = np.concatenate((lo[keep], mid[0], hi[::-1]))
    amplitude = np.concatenate((amp[keep], mid[1], amp[::-1]))
    flank = np.concatenate((np.full(int(keep.sum()), -1), mid[2], np.ones(end))).astype(int)
    force = np.concatenate((r[:end][keep], [np.nan] * len(mid[0]), r[:end][::-1]))
    w0 = system.w0
    ds = xr.Dataset(
        {"omega_rad_s": ("point", omega, {"units": "rad/s", "long_name": "forcing frequency"}),
         "gamma": ("point", omega / w0, {"long_name": "omega / w0"}),
         "amplitude_m": ("point", amplitude, {"units": "m", "long_name": "first-harmonic amplitude of the output DOF"}),
         "flank": ("point", flank, {"long_name": "-1 low-frequency flank, 0 peak, 1 high-frequency flank"}),
         "modal_forcing": ("point", force, {"units": "1/s^2"})},
        coords={"point": np.arange(omega.size)})
    ds.attrs.update(status=status.value, message=status.message, peak_amplitude_m=float(peak[0]),
                    peak_omega_rad_s=float(peak[1]), peak_gamma=float(peak[1] / w0), backbone_method=b.method,
                    backbone_status=b.status.value, output_dof=b.output_dof, harmonics=b.harmonics)
    return ds
