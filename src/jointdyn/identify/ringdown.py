"""A backbone (amplitude, frequency, damping ratio) from the free decay of one mode.

The ring-down practice of the modal-Iwan literature (docs/guide/identify.md):

1. the mode's band is found from the spectrum (the contiguous region around
   its peak above ``RingdownOptions.band_level`` of the peak, widened by
   ``RingdownOptions.band_margin`` on each side: the frequency drifts with the
   amplitude);
2. the signal is band-pass filtered forwards and backwards (zero phase:
   ``scipy.signal.sosfiltfilt`` of a Butterworth filter of order
   ``RingdownOptions.filter_order``, the record extended by
   ``RingdownOptions.pad_periods`` periods of odd extension at each end);
3. (the analytic signal z = y + i H[y], ``scipy.signal.hilbert``, gives the
   envelope drawn in figures; the points below do not use it: on a decaying
   record its end effects reached several percent of the damping ratio);
4. the first and last ``trim_periods`` periods, or more where the filter's
   slowest pole needs ``RingdownOptions.trim_decays`` time constants to die
   out, are dropped: the filter's transients live there (the result says how
   much was dropped);
5. between upward zero crossings, consecutive windows of ``cycles`` whole
   cycles give the frequency (cycles over the time taken: no derivative of a
   noisy phase) and, by linear least squares of y ~ A exp(r tau) cos(omega tau
   + phi) about the window's centre, the amplitude A;
6. the decay is not differentiated window by window (with 1 % noise the rate
   of a two-cycle window scatters by tens of percent): the smooth model
   -d ln A/dt = a0 + a1 A^p, omega = c0 - c1 A^p (viscous damping and a joint
   in microslip) is fitted to all windows at once, weighted by their noise,
   which is measured from the scatter (:mod:`._envelope`); the tail where the
   amplitude's error exceeds ``RingdownOptions.amplitude_rtol`` is dropped;
7. the damping ratio is EPMC's: the decay's -(d ln A/dt)/omega times
   :func:`epmc_factor` (the decay rate counts the energy stored at a turning
   point, EPMC the first-harmonic stiffness: 2.7 % apart at a quarter of the
   slip displacement of Iwan's law);
   where that model holds, the microslip joint's own decay (k + kt, R, chi, zeta of a unit
   modal mass: dissipation and softening tied by Masing's rule) is fitted to the windows
   next and gives the points (:func:`_masing_decay`);
8. a velocity or acceleration signal is turned into displacement amplitude
   by dividing by omega or omega^2 before the model is fitted.

Bad data raise ValueError: fewer than ``RingdownOptions.min_samples_per_period``
(10) samples per period at the top of the band (aliased), shorter than ``2 trim_periods + 2 cycles`` periods, no decay
(the envelope falls by less than ``RingdownOptions.min_decay``), two modes in
the band (a second spectral peak more prominent than
``RingdownOptions.second_peak`` of the peak).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._envelope import RingdownOptions, smooth_envelope

__all__ = ["RingdownBackbone", "RingdownOptions", "backbone_from_ringdown", "SIGNAL_KINDS"]

#: what the signal measures: displacement (m), velocity (m/s), acceleration (m/s^2)
SIGNAL_KINDS = ("x", "v", "a")


@dataclass(frozen=True)
class RingdownBackbone:
    """The backbone extracted from a ring-down.

    Attributes
    ----------
    amplitude_m, omega_rad_s, damping_ratio : ndarray
        One point per window, from the largest amplitude down (m, rad/s, -), of the decay
        model fitted to all windows (module docstring); the damping ratio is EPMC's
        (:func:`epmc_factor`). The columns of ``jointdyn fit --backbone``.
    band_rad_s : tuple
        The pass band of the zero-phase filter, rad/s.
    trimmed_s : tuple
        Seconds dropped at the start and at the end (end effects).
    t, envelope_m : ndarray
        The kept times, s, and the displacement envelope there, m (for figures).
    message : str
        One line on what was done.
    windows : dict or None
        The windows the decay model was fitted to: ``t`` (s), ``lna`` (ln of the displacement
        amplitude), ``omega`` (rad/s) and their standard errors ``sigma_lna`` and
        ``sigma_omega`` (rad/s), measured from the scatter, and ``form``: ``"microslip"`` where
        the decay model held, ``"spline"`` where it did not (a decay through macroslip). The
        points above come from one smooth model, so they are not independent data:
        :func:`jointdyn.identify.fit_ringdown` fits these instead (None: a RingdownBackbone made
        without windows, which fit_ringdown fits through its points).
    """

    amplitude_m: np.ndarray
    omega_rad_s: np.ndarray
    damping_ratio: np.ndarray
    band_rad_s: tuple
    trimmed_s: tuple
    t: np.ndarray
    envelope_m: np.ndarray
    message: str
    windows: dict | None = None


def epmc_factor(p, omega0, omega):
    """The damping ratio of EPMC over the decay's -(d ln A / dt) / omega at each frequency omega.

    EPMC's damping ratio is the energy dissipated per period over 2 pi m omega^2 A^2 (the
    first-harmonic stiffness times A^2); the decay rate is the energy per period over the
    slope of the energy stored at a turning point, which for a joint of Jenkins elements in
    parallel (Iwan, Segalman, discrete) is A (k + F'(A)), F' the tangent of the virgin curve:
    the two differ by (k + F') / (k + K1). In microslip K1 = kt - c1(chi) R A^(chi+1) and
    F' = kt - R A^(chi+1) / (chi+1), so with chi = p - 1 (the decay's exponent) and
    k + kt = m omega0^2, k + K1 = m omega^2:

        (k + F') / (k + K1) = 1 - (g - 1) (omega0^2 / omega^2 - 1),  g = 1 / ((chi+1) c1(chi)).

    For Iwan's law (p = 1) g = 2: 2.7 % at a quarter of the slip displacement.
    """
    from ._microslip import _c1

    chi = max(float(p) - 1.0, -0.99)
    g = 1.0 / ((chi + 1.0) * _c1(chi))
    return 1.0 - (g - 1.0) * np.maximum(omega0 * omega0 / (omega * omega) - 1.0, 0.0)


def _masing_decay(win, A, w, D, expo, w0):
    """(A, omega, D) at the windows of the microslip decay (:func:`._microslip.decay_model`, unit
    modal mass) fitted to them by least squares, from the power-law decay model's values.

    The power-law model's rate and frequency drop have coefficients of their own, tied only by
    their common exponent: over a decade of Segalman microslip with 1 % noise its exponent came
    out 0.34 to 0.44 for 0.5, and the damping ratio up to 6.7 % off EPMC's at the ends (3 seeds
    of 20 above 5 %). A joint of Jenkins elements dissipates and softens in a fixed ratio for a
    given exponent (its Masing loops), which is what the microslip decay holds (and what
    :func:`epmc_factor` already assumes): the frequency's drift then pins the exponent."""
    from ._microslip import _c1, decay_fit, microslip_model

    chi = float(np.clip(expo - 1.0, -0.9, 3.0))
    K = w0 * w0
    a_top = float(A[0])
    drop = max(K - float(w[0]) ** 2, 1e-9 * K)
    start = {"K": K, "R": drop / (_c1(chi) * a_top ** (chi + 1.0)), "chi": chi,
             "zeta": max(float(np.min(D)) * 0.5, 1e-7)}
    sol, _ = decay_fit(win, 1.0, start, True, profile=False, chi_bounds=(-0.9, 3.0))
    if not sol.converged:
        return A, w, D
    v = sol.values
    from ._microslip import decay_model

    lna, _ = decay_model(v, 1.0, win["t"], float(win["lna"][-1]))
    A = np.exp(lna)
    w, D = microslip_model(v["K"], v["R"], v["chi"], v["zeta"], 1.0, A)
    return A, w, D


def _uniform(t, y, name):
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.ndim != 1 or y.shape != t.shape:
        raise ValueError(f"t and {name} must be 1-D arrays of one length, got shapes {t.shape}, {y.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y))):
        raise ValueError(f"t and {name} must be finite")
    if t.size < 10:
        raise ValueError(f"a ring-down needs at least 10 samples, got {t.size}")
    dt = np.diff(t)
    h = float(np.median(dt))
    if not h > 0.0 or np.max(np.abs(dt - h)) > 1e-3 * h:
        raise ValueError("t must be sampled uniformly (constant step, strictly increasing)")
    return t, y, h


def _band(y, h, options):
    """(low, high) rad/s of the mode's band from the spectrum, and the peak, rad/s."""
    from scipy.signal import find_peaks

    spec = np.abs(np.fft.rfft((y - y.mean()) * np.hanning(y.size)))
    f = np.fft.rfftfreq(y.size, h) * 2.0 * math.pi
    spec[0] = 0.0
    ip = int(np.argmax(spec))
    lev = options.band_level * spec[ip]
    lo = ip
    while lo > 1 and spec[lo - 1] >= lev:
        lo -= 1
    hi = ip
    while hi < spec.size - 1 and spec[hi + 1] >= lev:
        hi += 1
    low, high = f[lo] / (1.0 + options.band_margin), f[hi] * (1.0 + options.band_margin)
    sel = (f >= low) & (f <= high)
    # smoothed over a few bins so that the ripple of one decaying mode is not a second peak
    win = max(3, int(0.01 * ip) | 1)
    smooth = np.convolve(spec, np.ones(win) / win, mode="same")
    peaks, _ = find_peaks(np.where(sel, smooth, 0.0), prominence=options.second_peak * smooth[ip])
    if peaks.size > 1:
        raise ValueError(f"two modes in the band {low:.4g} to {high:.4g} rad/s (spectral peaks at "
                         f"{', '.join(f'{f[p]:.4g}' for p in peaks[:4])} rad/s): the ring-down must excite one "
                         f"mode in its band; filter it or pass band=")
    return max(low, f[1]), high, f[ip]


def _local_decay(tau, y, om, corr):
    """(amplitude, its relative standard error) at tau = 0 of y ~ A exp(r tau) cos(om tau + phi)
    over one window: linear least squares of (c0 + c1 tau) cos + (d0 + d1 tau) sin, repeated
    on y exp(-r tau) so that the envelope's curvature does not bias A; the error from the
    residual variance, the samples counted as independent every ``corr``. The amplitude is
    sqrt(c0^2 + d0^2 - var c0 - var d0): without the variances the noise would raise it by
    about var / (2 A), which at the noisy end of a decay flattens the envelope."""
    r = 0.0
    c, s = np.cos(om * tau), np.sin(om * tau)
    X = np.column_stack([c, s, tau * c, tau * s])
    for _ in range(3):
        z = y * np.exp(-r * tau)
        coef, _, _, _ = np.linalg.lstsq(X, z, rcond=None)
        a2 = coef[0] ** 2 + coef[1] ** 2
        r += (coef[0] * coef[2] + coef[1] * coef[3]) / a2
    res = z - X @ coef
    s2 = float(res @ res) / max(tau.size - 4, 1) * corr
    cov = s2 * np.linalg.inv(X.T @ X)
    var_a = (coef[0] ** 2 * cov[0, 0] + coef[1] ** 2 * cov[1, 1] + 2.0 * coef[0] * coef[1] * cov[0, 1]) / a2
    amp = math.sqrt(max(a2 - cov[0, 0] - cov[1, 1], 0.25 * a2))
    return amp, math.sqrt(var_a) / amp


def _windows(tk, yk, tc, cycles, corr, rtol):
    """(centre s, amplitude, relative error, omega rad/s) of consecutive windows of ``cycles``
    whole cycles between the upward zero crossings ``tc``, and the seconds of tail dropped
    (from the first window whose amplitude error exceeds ``rtol``: in the noise)."""
    out = []
    dropped = 0.0
    for j in range(0, tc.size - cycles, cycles):
        e = j + cycles
        sel = slice(int(np.searchsorted(tk, tc[j])), int(np.searchsorted(tk, tc[e])))
        om = 2.0 * math.pi * cycles / (tc[e] - tc[j])
        centre = 0.5 * (tc[j] + tc[e])
        amp, rel = _local_decay(tk[sel] - centre, yk[sel], om, corr)
        if rel > rtol:
            dropped = float(tk[-1] - tc[j])
            break
        out.append((centre, amp, rel, om))
    return np.array(out).reshape(-1, 4).T, dropped


def backbone_from_ringdown(t, signal, kind: str = "x", *, band=None, trim_periods: float = 3.0,
                           cycles: int = 2, options: RingdownOptions | None = None) -> RingdownBackbone:
    """Frequency and damping ratio against amplitude from a free decay (module docstring).

    Parameters
    ----------
    t : array_like
        Uniformly spaced sample times, s.
    signal : array_like
        The measured signal: displacement (m), velocity (m/s) or acceleration (m/s^2).
    kind : {"x", "v", "a"}
        What ``signal`` is.
    band : (float, float), optional
        Pass band, rad/s (default: from the spectrum's peak).
    trim_periods : float
        Least periods dropped at each end (more where the filter needs it: module docstring).
    cycles : int
        Whole cycles per backbone point (>= 1).
    options : RingdownOptions, optional
        The band, the filter, the checks of the record, the envelope's smoothing and where the
        noise ends it (default ``RingdownOptions()``).

    Returns
    -------
    RingdownBackbone

    Raises
    ------
    ValueError
        Bad arrays, non-uniform t, an unknown ``kind``, and the bad data of the module
        docstring (aliased, too short, no decay, two modes in the band).
    """
    from scipy.signal import butter, hilbert, sosfiltfilt

    from .. import _validate as V

    V.choice("kind", kind, SIGNAL_KINDS)
    V.positive_int("cycles", cycles)
    options = RingdownOptions() if options is None else options
    if not isinstance(options, RingdownOptions):
        raise ValueError(f"options must be a RingdownOptions, got {type(options).__name__}")
    t, y, h = _uniform(t, signal, kind)
    if band is None:
        low, high, peak = _band(y, h, options)
    else:
        low, high = (float(b) for b in band)
        if not 0.0 < low < high:
            raise ValueError(f"band must be (low, high) with 0 < low < high rad/s, got {band!r}")
        peak = 0.5 * (low + high)
    per_period = 2.0 * math.pi / (high * h)
    if per_period < options.min_samples_per_period:
        raise ValueError(f"the signal has {per_period:.3g} samples per period at {high:.4g} rad/s, fewer than "
                         f"{options.min_samples_per_period}: aliased; sample faster")
    period = 2.0 * math.pi / peak
    need = (2.0 * trim_periods + 2.0 * cycles) * period
    if t[-1] - t[0] < need:
        raise ValueError(f"the record lasts {t[-1] - t[0]:.4g} s, shorter than the {need:.4g} s needed "
                         f"({2 * trim_periods:g} periods trimmed and two windows of {cycles} cycles)")
    nyq = math.pi / h
    sos = butter(options.filter_order, (low / nyq, min(high / nyq, 0.99)), btype="band", output="sos")
    # padded by odd extension over several periods: the continuation of an oscillation that
    # keeps the filter's start-up transient mostly outside the record
    pad = min(y.size - 1, int(options.pad_periods * period / h))
    yf = sosfiltfilt(sos, y - y.mean(), padlen=pad)
    # the filter's slowest pole: its transient must have died out in what is kept
    from scipy.signal import sos2zpk

    slowest = -math.log(float(np.max(np.abs(sos2zpk(sos)[1])))) / h
    trim = max(trim_periods * period, options.trim_decays / slowest)
    keep = (t >= t[0] + trim) & (t <= t[-1] - trim)
    if np.count_nonzero(keep) < 2.0 * cycles * period / h:
        raise ValueError(f"the record lasts {t[-1] - t[0]:.4g} s, shorter than the {2 * trim:.4g} s trimmed (end "
                         f"effects of the filter) and two windows of {cycles} cycles: record a longer decay")
    tk, yk = t[keep], yf[keep]
    up = np.flatnonzero((yk[:-1] < 0.0) & (yk[1:] >= 0.0))
    tc = tk[up] - yk[up] * (tk[up + 1] - tk[up]) / (yk[up + 1] - yk[up])  # upward zero crossings
    # noise: the filtered noise is correlated over about pi / bandwidth seconds
    corr = max(1.0, math.pi / ((high - low) * h))
    (centre, amp, rel, w), dropped = _windows(tk, yk, tc, cycles, corr, 1.0)
    if amp.size < 4 or not amp.min() < (1.0 - options.min_decay) * amp[0]:
        raise ValueError(f"no decay: the envelope falls by less than {100 * options.min_decay:g} % over "
                         f"the record above the noise; a ring-down is a free decay")
    power = {"x": 0, "v": 1, "a": 2}[kind]  # displacement amplitude = amplitude / omega^power
    keep_w, lna, rate, w, expo, w0, _, misfit, windows = smooth_envelope(
        centre, np.log(amp) - power * np.log(w), w, options)
    if keep_w < centre.size:
        dropped = max(dropped, float(tk[-1] - centre[keep_w]))
    centre = centre[:keep_w]
    A, D_decay = np.exp(lna), -rate / w
    D = D_decay * epmc_factor(expo, w0, w) if expo is not None else D_decay
    if expo is not None:  # the decay model's form held: the joint's microslip decay itself
        A, w, D = _masing_decay(windows, A, w, D, expo, w0)
    w_at = np.interp(tk, centre, w) if power else 1.0
    # for figures only (the points come from the local fits); of the whole filtered record, so
    # that the transform's own end effects fall in the trimmed parts
    env = np.abs(hilbert(yf))[keep] / w_at ** power
    trimmed = (float(tk[0] - t[0]), float(t[-1] - tk[-1]) + dropped)
    msg = (f"band {low:.4g} to {high:.4g} rad/s (zero-phase Butterworth, order {options.filter_order}); "
           f"amplitudes of {cycles}-cycle windows between zero crossings, " + (
           f"decay -d ln A/dt = a0 + a1 A^p fitted (p = {expo:.3g}; misfit {misfit:.3g} of a spline's), then a "
           f"microslip joint's own decay (Masing) to the windows, damping in EPMC's definition;"
           if expo is not None else
           f"not a microslip decay (misfit {misfit:.3g} of a spline's): ln A(t) by a cubic spline, damping the "
           f"decay's own -(d ln A/dt)/omega, not EPMC's;") + f" {trimmed[0]:.4g} s trimmed at the start and "
           f"{trimmed[1]:.4g} s at the end "
           f"(end effects: {trim / period:.3g} periods each{'; and the tail within the noise' if dropped else ''}); "
           f"{A.size} points")
    return RingdownBackbone(amplitude_m=A, omega_rad_s=w, damping_ratio=D, band_rad_s=(low, high),
                            trimmed_s=trimmed, t=tk, envelope_m=env, message=msg, windows=windows)
