"""A backbone (amplitude, frequency, damping ratio) from the free decay of one mode.

The ring-down practice of the modal-Iwan literature (docs/guide/identify.md):

1. the mode's band is found from the spectrum (the contiguous region around
   its peak above ``config.RINGDOWN_BAND_LEVEL`` of the peak, widened by
   ``config.RINGDOWN_BAND_MARGIN`` on each side: the frequency drifts with the
   amplitude);
2. the signal is band-pass filtered forwards and backwards (zero phase:
   ``scipy.signal.sosfiltfilt`` of a Butterworth filter);
3. (the analytic signal z = y + i H[y], ``scipy.signal.hilbert``, gives the
   envelope drawn in figures; the points below do not use it: on a decaying
   record its end effects reached several percent of the damping ratio);
4. the first and last ``trim_periods`` periods, or more where the filter's
   slowest pole needs ``config.RINGDOWN_TRIM_DECAYS`` time constants to die
   out, are dropped: the filter's transients live there (the result says how
   much was dropped);
5. between upward zero crossings, windows of ``cycles`` whole cycles give
   the frequency (cycles over the time taken: no derivative of a noisy
   phase) and, by linear least squares of y ~ A exp(r tau) cos(omega tau +
   phi) about the window's centre, the amplitude A and the decay rate r
   (damping ratio -r / omega); a window grows (doubling) until r is known to
   ``config.RINGDOWN_RATE_RTOL``, and the tail where no window reaches
   ``config.RINGDOWN_RATE_LIMIT`` is in the noise and dropped;
6. a velocity or acceleration signal is turned into displacement amplitude
   by dividing by omega or omega^2.

Bad data raise ValueError: fewer than 10 samples per period at the top of the
band (aliased), shorter than ``2 trim_periods + 2 cycles`` periods, no decay
(the envelope falls by less than ``config.RINGDOWN_MIN_DECAY``), two modes in
the band.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import config

__all__ = ["RingdownBackbone", "backbone_from_ringdown", "SIGNAL_KINDS"]

#: what the signal measures: displacement (m), velocity (m/s), acceleration (m/s^2)
SIGNAL_KINDS = ("x", "v", "a")


@dataclass(frozen=True)
class RingdownBackbone:
    """The backbone extracted from a ring-down.

    Attributes
    ----------
    amplitude_m, omega_rad_s, damping_ratio : ndarray
        One point per window, from the largest amplitude down (m, rad/s, -): the columns
        of ``jointdyn fit --backbone``.
    band_rad_s : tuple
        The pass band of the zero-phase filter, rad/s.
    trimmed_s : tuple
        Seconds dropped at the start and at the end (end effects).
    t, envelope_m : ndarray
        The kept times, s, and the displacement envelope there, m (for figures).
    message : str
        One line on what was done.
    """

    amplitude_m: np.ndarray
    omega_rad_s: np.ndarray
    damping_ratio: np.ndarray
    band_rad_s: tuple
    trimmed_s: tuple
    t: np.ndarray
    envelope_m: np.ndarray
    message: str


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


def _band(y, h):
    """(low, high) rad/s of the mode's band from the spectrum, and the peak, rad/s."""
    from scipy.signal import find_peaks

    spec = np.abs(np.fft.rfft((y - y.mean()) * np.hanning(y.size)))
    f = np.fft.rfftfreq(y.size, h) * 2.0 * math.pi
    spec[0] = 0.0
    ip = int(np.argmax(spec))
    lev = config.RINGDOWN_BAND_LEVEL * spec[ip]
    lo = ip
    while lo > 1 and spec[lo - 1] >= lev:
        lo -= 1
    hi = ip
    while hi < spec.size - 1 and spec[hi + 1] >= lev:
        hi += 1
    low, high = f[lo] / (1.0 + config.RINGDOWN_BAND_MARGIN), f[hi] * (1.0 + config.RINGDOWN_BAND_MARGIN)
    sel = (f >= low) & (f <= high)
    # smoothed over a few bins so that the ripple of one decaying mode is not a second peak
    win = max(3, int(0.01 * ip) | 1)
    smooth = np.convolve(spec, np.ones(win) / win, mode="same")
    peaks, _ = find_peaks(np.where(sel, smooth, 0.0), prominence=config.RINGDOWN_SECOND_PEAK * smooth[ip])
    if peaks.size > 1:
        raise ValueError(f"two modes in the band {low:.4g} to {high:.4g} rad/s (spectral peaks at "
                         f"{', '.join(f'{f[p]:.4g}' for p in peaks[:4])} rad/s): the ring-down must excite one "
                         f"mode in its band; filter it or pass band=")
    return max(low, f[1]), high, f[ip]


def _local_decay(tau, y, om, corr):
    """(amplitude, d ln A / dt, its standard error) at tau = 0 of y ~ A exp(r tau) cos(om tau +
    phi) over one window: linear least squares of (c0 + c1 tau) cos + (d0 + d1 tau) sin,
    repeated on y exp(-r tau) so that the envelope's curvature does not bias r; the error
    from the residual variance, the samples counted as independent every ``corr``."""
    r = 0.0
    c, s = np.cos(om * tau), np.sin(om * tau)
    X = np.column_stack([c, s, tau * c, tau * s])
    for _ in range(3):
        z = y * np.exp(-r * tau)
        coef, rss, _, _ = np.linalg.lstsq(X, z, rcond=None)
        a2 = coef[0] ** 2 + coef[1] ** 2
        r += (coef[0] * coef[2] + coef[1] * coef[3]) / a2
    res = z - X @ coef
    s2 = float(res @ res) / max(tau.size - 4, 1) * corr
    cov = s2 * np.linalg.inv(X.T @ X)
    se = math.sqrt((coef[0] ** 2 * cov[2, 2] + coef[1] ** 2 * cov[3, 3]) / (a2 * a2))
    return math.sqrt(a2), r, se


def backbone_from_ringdown(t, signal, kind: str = "x", *, band=None, trim_periods: float = 10.0,
                           cycles: int = 2) -> RingdownBackbone:
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
    t, y, h = _uniform(t, signal, kind)
    if band is None:
        low, high, peak = _band(y, h)
    else:
        low, high = (float(b) for b in band)
        if not 0.0 < low < high:
            raise ValueError(f"band must be (low, high) with 0 < low < high rad/s, got {band!r}")
        peak = 0.5 * (low + high)
    per_period = 2.0 * math.pi / (high * h)
    if per_period < config.RINGDOWN_MIN_SAMPLES_PER_PERIOD:
        raise ValueError(f"the signal has {per_period:.3g} samples per period at {high:.4g} rad/s, fewer than "
                         f"{config.RINGDOWN_MIN_SAMPLES_PER_PERIOD}: aliased; sample faster")
    period = 2.0 * math.pi / peak
    need = (2.0 * trim_periods + 2.0 * cycles) * period
    if t[-1] - t[0] < need:
        raise ValueError(f"the record lasts {t[-1] - t[0]:.4g} s, shorter than the {need:.4g} s needed "
                         f"({2 * trim_periods:g} periods trimmed and two windows of {cycles} cycles)")
    nyq = math.pi / h
    sos = butter(config.RINGDOWN_FILTER_ORDER, (low / nyq, min(high / nyq, 0.99)), btype="band", output="sos")
    # padded by odd extension over several periods: the continuation of an oscillation that
    # keeps the filter's start-up transient mostly outside the record
    pad = min(y.size - 1, int(config.RINGDOWN_PAD_PERIODS * period / h))
    yf = sosfiltfilt(sos, y - y.mean(), padlen=pad)
    # the filter's slowest pole: its transient must have died out in what is kept
    from scipy.signal import sos2zpk

    slowest = -math.log(float(np.max(np.abs(sos2zpk(sos)[1])))) / h
    trim = max(trim_periods * period, config.RINGDOWN_TRIM_DECAYS / slowest)
    keep = (t >= t[0] + trim) & (t <= t[-1] - trim)
    if np.count_nonzero(keep) < 2.0 * cycles * period / h:
        raise ValueError(f"the record lasts {t[-1] - t[0]:.4g} s, shorter than the {2 * trim:.4g} s trimmed (end "
                         f"effects of the filter) and two windows of {cycles} cycles: record a longer decay")
    tk, yk = t[keep], yf[keep]
    up = np.flatnonzero((yk[:-1] < 0.0) & (yk[1:] >= 0.0))
    tc = tk[up] - yk[up] * (tk[up + 1] - tk[up]) / (yk[up + 1] - yk[up])  # upward zero crossings
    # noise: the filtered noise is correlated over about pi / bandwidth seconds
    corr = max(1.0, math.pi / ((high - low) * h))
    A, w, D, centre = [], [], [], []
    j, dropped = 0, 0.0
    while j + cycles < tc.size:
        c, best = cycles, None
        while True:  # the shortest window whose decay rate is known to RINGDOWN_RATE_RTOL
            e = min(j + c, tc.size - 1)
            sel = slice(int(np.searchsorted(tk, tc[j])), int(np.searchsorted(tk, tc[e])))
            om = 2.0 * math.pi * (e - j) / (tc[e] - tc[j])
            amp, rate, se = _local_decay(tk[sel] - 0.5 * (tc[j] + tc[e]), yk[sel], om, corr)
            rel = se / abs(rate) if rate != 0.0 else math.inf
            if best is None or rel < best[0]:
                best = (rel, e, amp, rate, om)
            if rel <= config.RINGDOWN_RATE_RTOL or e >= tc.size - 1 or c >= config.RINGDOWN_MAX_CYCLES:
                break
            c *= 2
        rel, e, amp, rate, om = best
        if rel > config.RINGDOWN_RATE_LIMIT:  # the envelope is lost in the noise from here on
            dropped = float(tk[-1] - tc[j])
            break
        A.append(amp)
        w.append(om)
        D.append(-rate / om)
        centre.append(0.5 * (tc[j] + tc[e]))
        j = e
    A, w, D, centre = np.array(A), np.array(w), np.array(D), np.array(centre)
    if A.size < 2 or not A[-1] < (1.0 - config.RINGDOWN_MIN_DECAY) * A[0]:
        raise ValueError(f"no decay: the envelope falls by less than {100 * config.RINGDOWN_MIN_DECAY:g} % over "
                         f"the record; a ring-down is a free decay")
    power = {"x": 0, "v": 1, "a": 2}[kind]  # displacement amplitude = amplitude / omega^power
    w_at = np.interp(tk, centre, w) if power else 1.0
    # for figures only (the points come from the local fits); of the whole filtered record, so
    # that the transform's own end effects fall in the trimmed parts
    env = np.abs(hilbert(yf))[keep] / w_at ** power
    trimmed = (float(tk[0] - t[0]), float(t[-1] - tk[-1]) + dropped)
    msg = (f"band {low:.4g} to {high:.4g} rad/s (zero-phase Butterworth, order {config.RINGDOWN_FILTER_ORDER}); "
           f"local decay fits between zero crossings; {trimmed[0]:.4g} s trimmed at the start and "
           f"{trimmed[1]:.4g} s at the end "
           f"(end effects: {trim / period:.3g} periods each{'; and the tail within the noise' if dropped else ''}); "
           f"{A.size} points of {cycles} or more cycles (the decay rate of each to "
           f"{100 * config.RINGDOWN_RATE_RTOL:g} %)")
    return RingdownBackbone(amplitude_m=A / w ** power, omega_rad_s=w, damping_ratio=D, band_rad_s=(low, high),
                            trimmed_s=trimmed, t=tk, envelope_m=env, message=msg)
