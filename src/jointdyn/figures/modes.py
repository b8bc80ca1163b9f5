"""Nonlinear-mode figures.

``modes_backbones``
    Backbones of the paper's damper at its constant normal load (N0 =
    100 N): natural frequency and modal damping ratio against the
    first-harmonic amplitude, by the extended periodic motion concept
    (:func:`jointdyn.modes.epmc`, 7 harmonics, 128 samples) for the exact
    Iwan contact (``iwan``), the paper's closed form (``iwan-paper``) and one
    Jenkins element (``jenkins``), with the quasi-static estimate
    (:func:`jointdyn.modes.qsma`) of the exact Iwan contact. At constant load
    the steady cycles of the closed form are exact, so its backbone lies on
    the exact model's. A normal load that follows the motion: the same mass
    on a wedge (contact plane at :data:`WEDGE_DEG` to its motion), so that the
    motion slides the contact by x cos(theta) and loads the paper's normal
    spring by x sin(theta): N = max(0, N0 + kn x sin(theta)) rises and falls
    with the motion and the contact opens at large amplitude. Frequencies
    are in units of the paper's w0 = sqrt(k / m) for every curve.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._registry import model_label, pyplot, register_figure, save_figure

#: contact laws of the backbones (registered names)
BACKBONE_MODELS = ("iwan", "iwan-paper", "jenkins")
#: amplitude range in units of fy / kt
BACKBONE_Q = (1e-2, 1e2)
#: angle between the wedge's contact plane and the motion, degrees
WEDGE_DEG = 30.0
#: label of the wedge curve in the table's ``model`` column
WEDGE_LABEL = "iwan, wedge"


def wedge_system(theta_deg: float = WEDGE_DEG):
    """The paper's mass on a wedge: exact Iwan contact along x cos(theta), the
    paper's normal spring (kn, preload N0) along x sin(theta)."""
    from ..kinematics import NormalSpring
    from ..laws import make_law
    from ..systems import PAPER, Contact, System

    th = math.radians(theta_deg)
    law = make_law("iwan", kt=PAPER["kt"], mu=PAPER["mu"], n_ref=PAPER["n0"])
    contact = Contact(law, direction=[math.cos(th)],
                      normal=NormalSpring(kn=PAPER["kn"], preload=PAPER["n0"], direction=[math.sin(th)]))
    return System(np.array([[PAPER["m"]]]), None, np.array([[PAPER["k"]]]), contacts=(contact,), force=[0.0])


def backbones_data(models=BACKBONE_MODELS, q_range=BACKBONE_Q):
    """EPMC backbones of each model and the QSMA estimate of the first, as one table."""
    from ..modes import backbone_dataset, epmc, qsma
    from ..systems import PAPER, System

    scale = PAPER["mu"] * PAPER["n0"] / PAPER["kt"]
    amps = (q_range[0] * scale, q_range[1] * scale)
    w0 = math.sqrt(PAPER["k"] / PAPER["m"])
    runs = []
    for i, model in enumerate(models):
        system = System.paper_damper(eta=0.0, model=model)
        runs.append((model, "epmc", epmc(system, amps, progress=False)))
        if i == 0:
            runs.append((model, "qsma", qsma(system, amps)))
    runs.append((WEDGE_LABEL, "epmc", epmc(wedge_system(), amps, progress=False)))
    rows = []
    for model, method, b in runs:
        ds = backbone_dataset(b)
        df = pd.DataFrame({v: ds[v].values for v in ("amplitude_m", "amplitude_q", "omega_rad_s",
                                                      "damping_ratio")})
        df.insert(3, "gamma", df.omega_rad_s / w0)  # the paper's w0 for every curve
        df.insert(0, "method", method)
        df.insert(0, "model", model)
        df["status"] = ds.attrs["status"]
        rows.append(df)
    return {"backbones": pd.concat(rows, ignore_index=True)}


@register_figure("modes_backbones", "Backbones of the paper's damper: natural frequency and damping ratio against "
                 "amplitude (EPMC; exact Iwan, closed form, Jenkins at constant load; QSMA estimate; exact Iwan "
                 "with a normal load that follows the motion)", 80)
def modes_backbones():
    return backbones_data()


_STYLE = {("iwan", "epmc"): ("C0", "-", 2.4), ("iwan-paper", "epmc"): ("C1", "--", 1.4),
          ("jenkins", "epmc"): ("C3", "-", 1.4), ("iwan", "qsma"): ("k", ":", 1.4),
          (WEDGE_LABEL, "epmc"): ("C2", "-", 1.8)}


@modes_backbones.plotter
def _plot_modes_backbones(tables, out_dir):
    from ..systems import PAPER

    plt = pyplot()
    df = tables["backbones"]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.5, 7.5), sharex=True, layout="constrained")
    for (model, method), sub in df.groupby(["model", "method"], sort=False):
        color, ls, lw = _STYLE.get((model, method), ("0.5", "-", 1.0))
        label = f"{method.upper()}: {model_label(model)}"
        if model == WEDGE_LABEL:
            label = (f"EPMC: exact Iwan on a wedge ({WEDGE_DEG:g} deg): N = N0 + kn x sin(theta) follows "
                     "the motion")
        if model == "iwan-paper":
            label += " (on the exact curve at constant load)"
        ax1.plot(sub.amplitude_q, sub.gamma, ls, color=color, lw=lw)
        ax2.plot(sub.amplitude_q, sub.damping_ratio, ls, color=color, lw=lw, label=label)
    stuck = math.sqrt(1.0 + PAPER["kt"] / PAPER["k"])
    for g, text in ((stuck, "constant load, all stuck"), (1.0, "constant load, all slipping")):
        ax1.axhline(g, color="0.5", lw=0.8, ls=":", zorder=0)
        ax1.text(df.amplitude_q.min(), g, f" {text}, gamma = {g:.3f}", va="bottom", fontsize=7, color="0.3")
    ax1.set_ylabel("natural frequency omega / w0")
    ax2.set_ylabel("modal damping ratio")
    ax2.set_yscale("log")
    ax2.set_ylim(bottom=max(float(np.nanmin(df.damping_ratio[df.damping_ratio > 0])), 1e-5))
    ax2.set_xlabel("first-harmonic amplitude kt a / fy")
    for ax in (ax1, ax2):
        ax.set_xscale("log")
        ax.grid(alpha=0.3, which="both")
    # below the panels: inside, the legend would cover curves (they fill both axes)
    fig.legend(*ax2.get_legend_handles_labels(), loc="outside lower center", ncol=1, fontsize=7, frameon=False)
    fig.suptitle("Backbones of the paper's damper (H = 7): constant N0 = 100 N, and N following the motion",
                 fontsize=10)
    return save_figure(fig, out_dir, "modes_backbones")
