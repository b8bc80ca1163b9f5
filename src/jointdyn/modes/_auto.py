"""Harmonics and samples of an EPMC backbone chosen automatically, as
``frc --method hb`` chooses them for a branch.

A backbone is computed at the first level ``(H, Ns)``
(``config.HB_HARMONICS``, ``config.HB_SAMPLES``); at a few of its points
(spread over the amplitude range, and the point of largest damping) the
mode is solved again at fixed amplitude with 2H + 1 harmonics and with
2 Ns samples, by Newton from the point's own solution. Where the natural
frequency (relative to itself) or the damping ratio (relative to the
backbone's largest) changes by more than ``config.HB_AUTO_RTOL``, the
backbone is computed again at the finer level (the samples first: with
too few, the sampling error of a contact force that jumps where the
contact separates moves the solution with more harmonics too), up to
``auto_max_harmonics`` and ``auto_max_samples`` of the
:class:`~jointdyn.hb.options.HBOptions` given to :func:`~jointdyn.modes.epmc`. The
levels used and the last check are said in the backbone's message and
counters.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import config
from ..continuation import stage_note
from ..hb.discretisation import check_levels, level_number, next_level
from ..hb.levels import Discretisation

__all__ = ["auto_backbone", "check_points", "level_changes"]

def check_points(backbone) -> np.ndarray:
    """Indices of the points where a backbone's discretisation is checked:
    ``EPMCOptions.auto_check_points`` (those of its problem) spread evenly over its points, and
    the point of largest damping ratio."""
    p = backbone.points
    idx = np.round(np.linspace(0, p - 1, min(p, backbone.problem.options.auto_check_points))).astype(int)
    zeta = np.where(np.isfinite(backbone.damping_ratio), backbone.damping_ratio, -np.inf)
    return np.unique(np.r_[idx, int(np.argmax(zeta))])


def _padded(X, n: int, H: int) -> np.ndarray:
    """Harmonic coefficients X (any H) with harmonics 0..H (zero above X's own, cut above H)."""
    Xm = np.asarray(X, dtype=np.float64).reshape(-1, n)
    out = np.zeros((2 * H + 1, n))
    out[: min(Xm.shape[0], out.shape[0])] = Xm[: out.shape[0]]
    return out.ravel()


def level_changes(backbone, level, disc, mode: int) -> tuple:
    """(change with more harmonics, change with more samples) of the backbone
    computed at ``level`` with the discretisation ``disc`` (NaN: that check is not made; inf: its Newton
    failed): the largest over :func:`check_points` of the natural
    frequency's relative change and the damping ratio's change relative to
    the backbone's largest damping ratio."""
    b = backbone
    system, n = b.problem.system, b.problem.n
    zeta_scale = float(np.nanmax(np.abs(b.damping_ratio))) if b.points else 0.0
    changes = []
    for check in check_levels(level, disc):
        if check is None:
            changes.append(math.nan)
            continue
        problem = type(b.problem)(system, mode=mode, output_dof=b.output_dof, harmonics=check.harmonics,
                                   samples=check.samples, hb_options=b.problem.hb.options,
                                   epmc_options=b.problem.options)
        worst = 0.0
        for i in check_points(b):
            w, zeta = b.omega_rad_s[i], b.damping_ratio[i]
            guess = problem.pack(_padded(b.X[i], n, check.harmonics), w, b.xi_rad_s[i])
            v, ok, _ = problem.solve(b.amplitude_m[i], guess)
            if not ok:
                worst = math.inf
                break
            _, w2, xi2 = problem.unpack(v, math.log10(b.amplitude_m[i]))
            change = abs(w2 - w) / abs(w)
            if zeta_scale > 0:
                change = max(change, abs(xi2 / (2.0 * w2) - zeta) / zeta_scale)
            worst = max(worst, change)
        changes.append(worst)
    return tuple(changes)


def auto_backbone(fixed, system, amplitude, *, harmonics, samples, mode: int = 1, **kw):
    """The backbone of ``fixed(system, amplitude, harmonics=H, samples=Ns, mode=mode, **kw)`` (the EPMC
    at one level) at the coarsest level whose check passes (see the module docstring); ``harmonics`` and
    ``samples`` are integers or ``"auto"``; ``kw["hb_options"]`` bounds the levels."""
    disc = Discretisation.of(harmonics, samples)
    level = disc.first
    levels = [level]
    while True:
        k, most = level_number(level, disc, kw.get("hb_options"))
        stage_note(f"EPMC level {k}/{most}: H = {level.harmonics}, Ns = {level.samples}", kw.get("progress"))
        b = fixed(system, amplitude, harmonics=level.harmonics, samples=level.samples, mode=mode, **kw)
        if not b.points:
            return b
        ch = level_changes(b, level, disc, mode)
        bad = tuple(c > config.HB_AUTO_RTOL for c in ch)  # NaN (no check) compares False
        nxt = next_level(level, disc, *bad, kw.get("hb_options"))
        if nxt == level:
            break
        level = nxt
        levels.append(level)
    return _annotated(b, levels, ch, not any(bad))


def _annotated(b, levels, changes, converged: bool):
    """The backbone with the levels tried and the last check in its message and counters."""
    tried = ", ".join(f"H = {h}, Ns = {s}" for h, s in levels)
    shown = [f"{100 * c:.2g} % with {what}" for c, what in zip(changes, ("more harmonics", "more samples"))
             if not math.isnan(c)]
    note = (f"; harmonics and samples chosen automatically (tried {tried}; at the last, frequency and damping "
            f"change by {', '.join(shown) or 'nothing checked'}")
    note += ")" if converged else f", above the tolerance {100 * config.HB_AUTO_RTOL:g} % at the bound)"
    counters = {**b.counters, "discretisation_levels": len(levels), "discretisation_converged": int(converged)}
    return dataclasses.replace(b, message=b.message + note, counters=counters)
