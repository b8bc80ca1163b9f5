"""Identification figure: a ring-down, the backbone extracted from it, and the fitted model."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._registry import pyplot, register_figure, save_figure

#: the oscillator of the figure: m (kg), k (N/m), Iwan kt (N/m), fy (N), zeta; released from
#: RELEASE slip displacements, PERIODS periods at 64 samples per period, white noise of NOISE of
#: the record's peak (seed SEED), the mode's pass band BAND (rad/s: the frequency drifts from the
#: slipping to the stuck one, two spectral peaks): the decay through macroslip of
#: benchmarks/coverage_ringdown.py
M, K, KT, FY, ZETA = 2.0, 4e5, 1e5, 20.0, 0.002
RELEASE, PERIODS, NOISE, SEED, BAND = 5.0, 150, 0.01, 0, (300.0, 750.0)


def ringdown_data() -> dict:
    """The free decay (time integration, with noise), its extracted backbone, the model fitted to
    its windows as ``jointdyn fit --ringdown`` does (:func:`jointdyn.identify.fit_ringdown`), the
    true model's EPMC backbone, and what was trimmed (the filter's end effects and the noisy tail
    in time; the points outside the fit's damping range)."""
    import jointdyn as jd
    from jointdyn.dynamics.integrate import integrate_sampled
    from jointdyn.identify import fit_ringdown
    from jointdyn.modes import epmc

    law = jd.make_law("iwan", kt=KT, mu=FY / 100.0, n_ref=100.0)
    system = jd.System.sdof(m=M, k=K, law=law, c=2 * ZETA * math.sqrt((K + KT) * M))
    period = 2.0 * math.pi / math.sqrt((K + KT) / M)
    t = np.arange(0.0, PERIODS * period, period / 64)
    run = integrate_sampled(system, t, np.zeros((t.size, 1)), np.full((t.size, 1), 100.0),
                            x0=[RELEASE * law.x_slip])
    x = run.x[np.searchsorted(run.t, t), 0]
    x = x + NOISE * np.max(np.abs(x)) * np.random.default_rng(SEED).normal(size=x.size)
    b = jd.backbone_from_ringdown(t, x, "x", band=BAND)
    fit = fit_ringdown(b, mass=M, model="iwan")
    rng = fit.damping_range
    bb = epmc(system, (0.5 * b.amplitude_m.min(), 1.5 * b.amplitude_m.max()), harmonics=3, progress=False)
    signal = pd.DataFrame({"t_s": t, "x_m": x})
    kept = b.t <= t[-1] - b.trimmed_s[1]  # without the tail dropped within the noise
    envelope = pd.DataFrame({"t_s": b.t[kept], "envelope_m": b.envelope_m[kept]})
    backbone = pd.DataFrame({"amplitude_m": b.amplitude_m, "omega_rad_s": b.omega_rad_s,
                             "damping_ratio": b.damping_ratio, "omega_fit_rad_s": fit.fitted["omega_rad_s"],
                             "damping_fit": fit.fitted["damping_ratio"],
                             "damping_determined": np.array(rng["determined"], int),
                             "damping_half_width": rng["half_width"], "status": fit.status.value})
    trimmed = pd.DataFrame({"start_s": [t[0], t[-1] - b.trimmed_s[1]], "end_s": [t[0] + b.trimmed_s[0], t[-1]],
                            "what": ["end effects of the filter", "end effects of the filter and the tail "
                                                                  "within the noise"]})
    reference = pd.DataFrame({"amplitude_m": bb.amplitude_m, "omega_rad_s": bb.omega_rad_s,
                              "damping_ratio": bb.damping_ratio})
    return {"signal": signal, "envelope": envelope, "backbone": backbone, "trimmed": trimmed, "epmc": reference}


@register_figure("ringdown_fit", "A ring-down of an oscillator with an Iwan joint (jointdyn's time integration), "
                 "the backbone extracted from it and the fitted modal Iwan model", 90)
def ringdown_fit():
    return ringdown_data()


@ringdown_fit.plotter
def _plot_ringdown_fit(tables, out_dir):
    plt = pyplot()
    s, e, b, tr, ref = (tables[k] for k in ("signal", "envelope", "backbone", "trimmed", "epmc"))
    fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(7.0, 9.0), layout="constrained")
    a1.plot(s.t_s, s.x_m * 1e3, color="0.6", lw=0.4, label="signal x(t), 1 % noise")
    a1.plot(e.t_s, e.envelope_m * 1e3, color="C0", lw=1.2, label="envelope of the band-passed signal (kept part)")
    for i, row in enumerate(tr.itertuples()):
        a1.axvspan(row.start_s, row.end_s, color="C3", alpha=0.12, lw=0,
                   label="trimmed: end effects of the filter, the tail within the noise" if i == 0 else None)
    a1.set_xlabel("t (s)")
    a1.set_ylabel("x (mm)")
    inside = b.damping_determined.astype(bool)
    A = b.amplitude_m * 1e3
    for ax, col, fit_col, ref_col in ((a2, "omega_rad_s", "omega_fit_rad_s", "omega_rad_s"),
                                      (a3, "damping_ratio", "damping_fit", "damping_ratio")):
        ax.plot(ref.amplitude_m * 1e3, ref[ref_col], "--", color="0.2", lw=0.9,
                label="EPMC backbone of the true model (reference)")
        ax.plot(A[inside], b[col][inside], "o", ms=4, color="0.35", label="extracted backbone")
        ax.plot(A[~inside], b[col][~inside], "o", ms=4, mfc="none", color="C3",
                label="extracted, trimmed: damping ratio not within +-5 % (95 %)")
        ax.plot(A, b[fit_col], color="C1", lw=1.4, label=f"model fitted to the windows ({b.status.iloc[0]})")
        if inside.any():
            ax.axvspan(A[inside].min(), A[inside].max(), color="C2", alpha=0.08, lw=0)
    a2.set_ylabel("omega (rad/s)")
    a3.set_ylabel("damping ratio (points: the decay's own, fit: EPMC's)")
    for ax in (a2, a3):
        ax.set_xscale("log")
        ax.set_xlabel("amplitude (mm); shaded: the damping range the fit reports")
    for ax in (a1, a2, a3):
        ax.grid(alpha=0.3, which="both")
    handles = [h for ax in (a1, a2) for h in ax.get_legend_handles_labels()[0]]
    labels = [lab for ax in (a1, a2) for lab in ax.get_legend_handles_labels()[1]]
    fig.legend(handles, labels, loc="outside lower center", ncol=1, fontsize=7, frameon=False)
    fig.suptitle(f"Ring-down to backbone to model (Iwan joint, released from {RELEASE:g} slip displacements)",
                 fontsize=10)
    return save_figure(fig, out_dir, "ringdown_fit")
