"""Identification figure: a ring-down, the backbone extracted from it, and the fitted model."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._registry import pyplot, register_figure, save_figure

#: the oscillator of the figure: m (kg), k (N/m), Iwan kt (N/m), fy (N), zeta; released from
#: RELEASE slip displacements, PERIODS periods at 64 samples per period
M, K, KT, FY, ZETA = 2.0, 4e5, 1e5, 20.0, 0.002
RELEASE, PERIODS = 30.0, 200


def ringdown_data() -> dict:
    """The free decay (time integration), its extracted backbone and the fitted model's."""
    import jointdyn as jd
    from jointdyn.dynamics.integrate import integrate_sampled

    law = jd.make_law("iwan", kt=KT, mu=FY / 100.0, n_ref=100.0)
    system = jd.System.sdof(m=M, k=K, law=law, c=2 * ZETA * math.sqrt((K + KT) * M))
    period = 2.0 * math.pi / math.sqrt((K + KT) / M)
    t = np.arange(0.0, PERIODS * period, period / 64)
    run = integrate_sampled(system, t, np.zeros((t.size, 1)), np.full((t.size, 1), 100.0),
                            x0=[RELEASE * law.x_slip])
    x = run.x[np.searchsorted(run.t, t), 0]
    b = jd.backbone_from_ringdown(t, x, "x")
    fit = jd.fit_backbone(b.amplitude_m, b.omega_rad_s, b.damping_ratio, mass=M, model="iwan")
    signal = pd.DataFrame({"t_s": t, "x_m": x})
    envelope = pd.DataFrame({"t_s": b.t, "envelope_m": b.envelope_m})
    backbone = pd.DataFrame({"amplitude_m": b.amplitude_m, "omega_rad_s": b.omega_rad_s,
                             "damping_ratio": b.damping_ratio, "omega_fit_rad_s": fit.fitted["omega_rad_s"],
                             "damping_fit": fit.fitted["damping_ratio"], "status": fit.status.value})
    return {"signal": signal, "envelope": envelope, "backbone": backbone}


@register_figure("ringdown_fit", "A ring-down of an oscillator with an Iwan joint (jointdyn's time integration), "
                 "the backbone extracted from it and the fitted modal Iwan model", 90)
def ringdown_fit():
    return ringdown_data()


@ringdown_fit.plotter
def _plot_ringdown_fit(tables, out_dir):
    plt = pyplot()
    s, e, b = tables["signal"], tables["envelope"], tables["backbone"]
    fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(7.0, 8.5), layout="constrained")
    a1.plot(s.t_s, s.x_m * 1e3, color="0.6", lw=0.4, label="signal x(t)")
    a1.plot(e.t_s, e.envelope_m * 1e3, color="C0", lw=1.2, label="envelope of the band-passed signal (kept part)")
    a1.set_xlabel("t (s)")
    a1.set_ylabel("x (mm)")
    a2.plot(b.amplitude_m * 1e3, b.omega_rad_s, "o", ms=3, color="0.4", label="extracted backbone")
    a2.plot(b.amplitude_m * 1e3, b.omega_fit_rad_s, color="C1", lw=1.4,
            label=f"fitted modal Iwan model ({b.status.iloc[0]})")
    a2.set_ylabel("omega (rad/s)")
    a3.plot(b.amplitude_m * 1e3, b.damping_ratio, "o", ms=3, color="0.4")
    a3.plot(b.amplitude_m * 1e3, b.damping_fit, color="C1", lw=1.4)
    a3.set_ylabel("damping ratio")
    for ax in (a2, a3):
        ax.set_xscale("log")
        ax.set_xlabel("amplitude (mm)")
    for ax in (a1, a2, a3):
        ax.grid(alpha=0.3, which="both")
    handles = [h for ax in (a1, a2) for h in ax.get_legend_handles_labels()[0]]
    labels = [lab for ax in (a1, a2) for lab in ax.get_legend_handles_labels()[1]]
    fig.legend(handles, labels, loc="outside lower center", ncol=1, fontsize=7, frameon=False)
    fig.suptitle("Ring-down to backbone to model (Iwan joint, released from 30 slip displacements)", fontsize=10)
    return save_figure(fig, out_dir, "ringdown_fit")
