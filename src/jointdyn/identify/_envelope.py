"""The decay envelope of a ring-down as a smooth model fitted to all windows at once.

The damping ratio of a ring-down is -(d ln A / dt) / omega. Differentiating
the amplitudes of short windows amplifies their noise (with 1 % noise of the
record's peak, a two-cycle window's decay rate scatters by tens of percent
at the end of a decay); growing each window until its rate is known trades
that for long windows over which the damping changes, and a spline through
ln A(t) with knots chosen by cross-validation still gave errors of 20 % and
more at its ends (measured on the Iwan decays of tests/test_identify_ringdown.py).
Here every window keeps its few cycles and gives ln A; the decay model

    -d ln A / dt = a0 + b (A / A0)^p,    omega = c0 - c1 (A / A0)^p,

viscous damping plus a joint in microslip (whose energy per cycle rises as
A^(chi+3) and whose first-harmonic stiffness falls as A^(chi+1), so that both
go as A^p with p = chi + 1), integrates in closed form and is fitted to all
windows by weighted least squares (:func:`smooth_envelope`). It does not hold
in macroslip: a decay from there is fitted from where it is in microslip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["RingdownOptions", "smooth_envelope"]


@dataclass(frozen=True)
class RingdownOptions:
    """Numbers of a ring-down's analysis (:func:`jointdyn.backbone_from_ringdown`): the mode's
    band, the band-pass filter, the checks of the record, and the envelope smoothing
    (:func:`smooth_envelope`).

    Attributes
    ----------
    band_level : float
        The mode's band is where the spectrum stays above this fraction of its peak (-).
    band_margin : float
        ... widened by this fraction of its edge frequencies on each side (-): the frequency
        drifts with the amplitude.
    second_peak : float
        A second spectral peak in the band more prominent than this fraction of the peak is a
        second mode (the record is refused) (-).
    filter_order : int
        Butterworth order of the zero-phase band-pass.
    min_samples_per_period : int
        Fewest samples per period at the top of the band (else the record is refused as
        aliased).
    min_decay : float
        Least relative fall of the envelope over the record (-); else the record is refused
        (no decay).
    pad_periods : float
        Periods of odd extension at each end of the record before the zero-phase filter.
    amplitude_rtol : float
        A window whose amplitude has a relative standard error above this is in the
        noise; from the first such window on, the tail is dropped (-).
    min_windows_per_knot : int
        Fewest windows between two knots of the spline that the decay model's misfit is
        measured against.
    misfit_limit : float
        Where the decay model's weighted rms residual exceeds this many times that of a
        cubic spline (knots every 0.25 of ln A), the decay is not of the microslip form (a
        decay through macroslip): ln A(t) and omega(t) are then the spline's, knots chosen by
        generalised cross-validation, and the damping ratio is the decay's own.
    trim_decays : float
        Time constants of the band-pass filter's slowest pole trimmed at each end of the
        record (its transients; with the odd extension before filtering, 4 left at most
        1 % on the damping ratio of the first windows of a decay from macroslip, 2 left 6 %).
    """

    band_level: float = 0.05
    band_margin: float = 0.15
    second_peak: float = 0.2
    filter_order: int = 4
    min_samples_per_period: int = 10
    min_decay: float = 0.1
    pad_periods: float = 10.0
    amplitude_rtol: float = 0.03
    min_windows_per_knot: int = 4
    trim_decays: float = 4.0
    misfit_limit: float = 3.0

    def __post_init__(self) -> None:
        from .. import _validate as V

        V.in_range("band_level", self.band_level, 0.0, 1.0, lo_open=True, hi_open=True)
        V.nonnegative("band_margin", self.band_margin)
        V.in_range("second_peak", self.second_peak, 0.0, 1.0, lo_open=True)
        V.positive_int("filter_order", self.filter_order)
        V.positive_int("min_samples_per_period", self.min_samples_per_period, minimum=2)
        V.in_range("min_decay", self.min_decay, 0.0, 1.0, lo_open=True, hi_open=True)
        V.nonnegative("pad_periods", self.pad_periods)
        if not 0.0 < self.amplitude_rtol < 1.0:
            raise ValueError(f"amplitude_rtol must be in (0, 1), got {self.amplitude_rtol!r}")
        if not self.misfit_limit > 1.0:
            raise ValueError(f"misfit_limit must be > 1 (allowed range (1, inf)), got {self.misfit_limit!r}")
        if not self.trim_decays > 0.0:
            raise ValueError(f"trim_decays must be > 0 (allowed range (0, inf)), got {self.trim_decays!r}")
        if not (isinstance(self.min_windows_per_knot, int) and self.min_windows_per_knot >= 2):
            raise ValueError(f"min_windows_per_knot must be an integer >= 2, got {self.min_windows_per_knot!r}")


def _knots(t, lna, fall, min_per):
    """Interior knots at falls ``fall`` of a running minimum of ln A (monotone in t)."""
    level = np.minimum.accumulate(lna)
    marks = np.arange(level[0] - fall, level[-1], -fall)
    idx = np.searchsorted(-level, -marks)  # first window at or below each mark
    inner = []
    last = 0
    for i in idx:
        if i - last >= min_per and t.size - 1 - i >= min_per:
            inner.append(t[i])
            last = i
    return np.array(inner)


def _fit(t, y, w, inner):
    from scipy.interpolate import make_lsq_spline

    knots = np.concatenate(([t[0]] * 4, inner, [t[-1]] * 4))
    spl = make_lsq_spline(t, y, knots, k=3, w=w)
    r = (spl(t) - y) * w
    return spl, float(r @ r), knots.size - 4


def _spline_envelope(t, lna, omega, options):
    """The fallback of :func:`smooth_envelope` for a decay not of the microslip form: cubic
    least-squares splines of ln A and omega, weighted by A, knots at equal falls of ln A chosen
    by generalised cross-validation; the noise and the tail as there."""
    amp = np.exp(lna)

    def best(t_, y_, w_):
        out = None
        for fall in (0.1, 0.15, 0.25, 0.4, 0.6, 1.0):
            inner = _knots(t_, y_, fall, options.min_windows_per_knot)
            spl, rss, p = _fit(t_, y_, w_, inner)
            if t_.size - p >= 2:
                gcv = t_.size * rss / (t_.size - p) ** 2
                if out is None or gcv < out[0]:
                    out = (gcv, spl, inner)
        return (out[1], out[2]) if out else (_fit(t_, y_, w_, np.array([]))[0], np.array([]))

    spl, _ = best(t, lna, amp)
    r = (spl(t) - lna) * amp
    noise = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    bad = np.flatnonzero(noise / np.exp(spl(t)) > options.amplitude_rtol)
    keep = max(int(bad[0]) if bad.size else t.size, min(t.size, 6))
    t, lna, omega, amp = t[:keep], lna[:keep], omega[:keep], amp[:keep]
    spl, inner = best(t, lna, amp)
    wfit = _fit(t, omega, amp, inner)[0]
    rw = wfit(t) - omega
    noise_w = max(1.4826 * float(np.median(np.abs(rw - np.median(rw)))), 1e-12 * float(np.max(omega)))
    # the windows for a fit of a law's own decay (through macroslip): ln A with the noise's bias
    # removed as in smooth_envelope, standard errors from the scatter about the splines
    lnc = 0.5 * np.log(np.maximum(amp * amp - 2.0 * noise * noise, 0.25 * amp * amp))
    windows = {"t": t, "lna": lnc, "omega": omega, "sigma_lna": noise / np.exp(lnc),
               "sigma_omega": np.full(keep, noise_w), "form": "spline"}
    return keep, spl(t), spl.derivative()(t), wfit(t), noise, windows


def power_decay(t, lna0, a0, b, p):
    """ln A(t) of d ln A / dt = -(a0 + b (A / A0)^p) from ln A0 at t = 0: with u = (A / A0)^p the
    equation is logistic, u = a0 e / (a0 + b (1 - e)), e = exp(-p a0 t)."""
    e = np.exp(-p * a0 * t)
    if a0 > 1e-9 * b:
        u = a0 * e / (a0 + b * (1.0 - e))
    else:  # no linear damping: u = 1 / (1 + p b t)
        u = 1.0 / (1.0 + p * b * t)
    return lna0 + np.log(np.maximum(u, 1e-300)) / p


def _fit_decay(t, lna, omega, w, sw=None):
    """Weighted least squares of :func:`power_decay` to (t, ln A) and of omega = c0 - c1 (A / A0)^p
    to omega with the same p: (lna0, a0, b, p, c0, c1) and the residuals of ln A (times ``w``)
    and of omega (rad/s); from several exponents p, the best. ``sw``: the standard error of
    omega relative to that of A (None: omega is fitted after ln A, with p held)."""
    from scipy.optimize import least_squares

    t0 = t - t[0]
    scale = np.max(w)
    w = w / scale  # residuals of order one: least squares' tolerances are absolute
    n = max(3, t.size // 4)
    s_first = max(-np.polyfit(t0[:n], lna[:n], 1)[0], 1e-12)
    s_last = max(-np.polyfit(t0[-n:], lna[-n:], 1)[0], 1e-12)
    a0 = min(s_first, s_last)
    b = max(s_first - a0, 1e-3 * s_first)
    wref = float(np.max(omega))

    def parts(v):
        lf = power_decay(t0, *v[:4])
        u = np.exp(v[3] * (lf - v[0]))
        return lf, v[4] - v[5] * u

    def res(v):
        lf, om = parts(v)
        r = (lf - lna) * w
        return r if sw is None else np.concatenate((r, (om - omega) / (sw * scale)))

    best = None
    for p0 in (0.3, 0.6, 1.0, 1.5, 2.5):
        v0 = [lna[0], a0, b, p0, wref, 0.0]
        lo = [-np.inf, 0.0, 0.0, 0.02, -np.inf, -np.inf]
        hi = [np.inf, np.inf, np.inf, 4.0, np.inf, np.inf]
        if sw is None:  # ln A alone (omega's coefficients are not in it)
            sol = least_squares(lambda v: res(np.r_[v, wref, 0.0]), v0[:4], bounds=(lo[:4], hi[:4]),
                                x_scale=[0.01, 0.1 * s_first, 0.1 * s_first, 0.1], method="trf")
            x = np.r_[sol.x, wref, 0.0]
        else:
            sol = least_squares(res, v0, bounds=(lo, hi), x_scale=[0.01, 0.1 * s_first, 0.1 * s_first, 0.1,
                                                                  1e-3 * wref, 1e-3 * wref], method="trf")
            x = sol.x
        if best is None or sol.cost < best[0]:
            best = (sol.cost, x)
    x = best[1]
    if sw is None:  # omega's line at the exponent found
        u = np.exp(x[3] * (parts(x)[0] - x[0]))
        x[4:] = np.linalg.lstsq(np.column_stack([np.ones(t.size), -u]), omega, rcond=None)[0]
    lf, om = parts(x)
    return x, (lf - lna) * w * scale, om - omega


def smooth_envelope(t, lna, omega, options: RingdownOptions) -> tuple:
    """The decay of ln A(t) and omega as smooth models, at the windows' centres ``t``.

    The decay rate is modelled as -d ln A / dt = a0 + a1 A^p (viscous damping, and a joint in
    microslip, whose energy per cycle rises as a power of the amplitude: A^3 for Iwan's law,
    A^(chi+3) for Segalman's), which integrates in closed form (:func:`power_decay`), and the
    frequency as omega = c0 - c1 A^p (the first-harmonic stiffness of the same microslip);
    (lna0, a0, a1, p) by weighted least squares of ln A, (c0, c1) by linear least squares.
    The noise of a window's amplitude is about the same in metres at every amplitude (the
    band-passed noise of the record), so ln A has a standard error proportional to 1 / A:
    the weights. Its size is measured from the scatter about a first fit (the in-band noise
    is absorbed by each window's own fit, so a window's residual does not show it); the
    windows from the first whose relative error exceeds ``options.amplitude_rtol`` on are in
    the noise and dropped, and the rest fitted again.

    Parameters
    ----------
    t : ndarray
        Window centres, s (increasing).
    lna : ndarray
        ln of each window's amplitude.
    omega : ndarray
        Each window's frequency, rad/s (cycles over time).
    options : RingdownOptions

    Returns
    -------
    keep : int
        How many windows (from the first) are above the noise; the arrays below have this length.
    lna_fit, rate, omega_fit : ndarray
        The smooth ln A, d ln A / dt (1/s) and omega (rad/s) at ``t[:keep]``.
    exponent : float or None
        p (None: the decay is not of this form, the spline's values are returned).
    omega0 : float or None
        c0, the frequency the model extrapolates to at zero amplitude, rad/s.
    noise : float
        The amplitude's standard error, in the units of exp(lna).
    misfit : float
        The rms of the weighted residual of ln A over that of a cubic spline with knots every
        0.25 of ln A (near 1: the model is adequate; above: the decay is not of this form).
    windows : dict
        The kept windows: ``t`` (s), ``lna`` (ln A with the noise's bias removed), ``omega``
        (rad/s), and their standard errors ``sigma_lna`` (-, per window: the amplitude's noise
        over A) and ``sigma_omega`` (rad/s), for fits of a model to the windows themselves
        (:func:`jointdyn.identify.fit_ringdown`); ``form`` is ``"microslip"`` where the decay
        model held and ``"spline"`` where it did not (a decay through macroslip: errors from the
        scatter about the splines).
    """
    amp = np.exp(lna)
    x, r, rw = _fit_decay(t, lna, omega, amp)
    inner = _knots(t, lna, 0.25, options.min_windows_per_knot)
    if t.size - inner.size - 4 >= 2:
        rs = _fit(t, lna, amp, inner)[1]
        misfit = math.sqrt((float(r @ r) / max(t.size - 4, 1)) / max(rs / (t.size - inner.size - 4), 1e-300))
        if misfit > options.misfit_limit:
            keep, lf, rate, wfit, noise, windows = _spline_envelope(t, lna, omega, options)
            return keep, lf, rate, wfit, None, None, noise, misfit, windows
    noise = 1.4826 * float(np.median(np.abs(r - np.median(r))))  # robust scale (MAD)
    fit0 = power_decay(t - t[0], *x[:4])
    bad = np.flatnonzero(noise / np.exp(fit0) > options.amplitude_rtol)
    keep = max(int(bad[0]) if bad.size else t.size, min(t.size, 6))
    t, lna, omega, amp = t[:keep], lna[:keep], omega[:keep], amp[:keep]
    # noise raises a measured amplitude: E|A + n|^2 = A^2 + 2 s^2 for a complex error of s per
    # component (s the amplitude's own scatter); at the end of a decay that flattens the
    # envelope (-6 % on the damping ratio of Segalman's law at 1 % noise without this)
    lna = 0.5 * np.log(np.maximum(amp * amp - 2.0 * noise * noise, 0.25 * amp * amp))
    amp = np.exp(lna)
    # omega's own noise, from its best power law alone (the decay's exponent may be off here)
    u = np.exp(fit0[:keep] - fit0[0])
    rw = min((omega - np.column_stack([np.ones(keep), -u ** q]) @ np.linalg.lstsq(
        np.column_stack([np.ones(keep), -u ** q]), omega, rcond=None)[0] for q in np.linspace(0.1, 3.0, 30)),
        key=lambda r_: float(r_ @ r_))
    noise_w = 1.4826 * float(np.median(np.abs(rw - np.median(rw))))
    x, r, rw = _fit_decay(t, lna, omega, amp, sw=max(noise_w, 1e-12 * float(np.max(omega))) / max(noise, 1e-300))
    lf = power_decay(t - t[0], *x[:4])
    Ap = np.exp(x[3] * (lf - x[0]))  # (A / A0)^p
    rate = -(x[1] + x[2] * Ap)
    wfit = x[4] - x[5] * Ap
    inner = _knots(t, lna, 0.25, options.min_windows_per_knot)
    rs = _fit(t, lna, amp, inner)[1] if t.size - inner.size - 4 >= 2 else float(r @ r)
    dof_m, dof_s = max(keep - 4, 1), max(keep - inner.size - 4, 1)
    misfit = math.sqrt((float(r @ r) / dof_m) / max(rs / dof_s, 1e-300))
    windows = {"t": t, "lna": lna, "omega": omega, "sigma_lna": noise / amp,
               "sigma_omega": np.full(keep, max(noise_w, 1e-12 * float(np.max(omega)))), "form": "microslip"}
    return keep, lf, rate, wfit, float(x[3]), float(x[4]), noise, misfit, windows
