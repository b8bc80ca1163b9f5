"""Harmonic-balance figures.

``fig6_hb``
    The Fig 6 cases (eta = 0.01, 0.5, 1.5, 10; a few beta) by harmonic
    balance and arc-length continuation (:func:`jointdyn.hb.frc_hb`, the
    default model ``iwan``, the exact Iwan model; harmonics and samples
    chosen automatically),
    stable parts solid, unstable parts
    dashed, folds marked, overlaid on the time-domain steady states of
    up and down sweeps (:func:`jointdyn.sweeps.frc_sweep`) on a coarse grid.
    A branch stopped as ``unbounded`` (beta below the Den Hartog limit) is
    drawn up to where it was stopped, from both ends.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import config
from ._registry import model_label, pyplot, register_figure, save_figure
from .curves import branch_pieces

#: cases of fig6_hb (kept small: one HB branch is ~0.1-1 s, the time-domain
#: sweep dominates the compute time)
HB_ETAS = (0.01, 0.5, 1.5, 10.0)
HB_BETAS = (0.5, 2.0, 20.0)
HB_GAMMA = (0.6, 1.8)
HB_TIME_GAMMA_STEP = 0.04


def fig6_hb_data(etas=HB_ETAS, betas=HB_BETAS, gamma=HB_GAMMA, time_step=HB_TIME_GAMMA_STEP, time_domain=True,
                 model=config.MODEL):
    """HB branches and time-domain points of the Fig 6 cases as two tables."""
    from ..hb import frc_hb
    from ..systems import System

    rows = []
    for eta in etas:
        for beta in betas:
            # default settings: harmonics and samples chosen per branch by the check of its peaks
            # (docs/hb-robustness.md)
            ds = frc_hb(System.paper_damper(eta=eta, beta=beta, model=model), gamma[0], gamma[1], progress=False)
            df = pd.DataFrame({v: ds[v].values for v in ("gamma", "amplitude_q", "offset_m", "stable", "fold",
                                                          "gap", "branch", "point_status")})
            df.insert(0, "beta", beta)
            df.insert(0, "eta", eta)
            df["status"] = ds.attrs["status"]
            df["model"] = model
            rows.append(df)
    tables = {"hb": pd.concat(rows, ignore_index=True)}
    if time_domain:
        from ..sweeps import frc_sweep, to_frame

        g = np.round(np.arange(gamma[0], gamma[1] + 1e-9, time_step), 10)
        td = to_frame(frc_sweep(g, etas=etas, betas=betas, directions=("up", "down"), model=model, progress=False))
        tables["time"] = td[["eta", "beta", "direction", "gamma", "amplitude_q", "status_name"]]
    return tables


@register_figure("fig6_hb", "Paper Fig 6 cases by harmonic balance (stable solid, unstable dashed, folds) over "
                 "time-domain sweeps; eta by panel, beta by colour; exact Iwan model", 65)
def fig6_hb():
    return fig6_hb_data()


def _runs(mask):
    """Index runs where ``mask`` holds (consecutive)."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(idx) > 1) + 1
    return np.split(idx, cuts)


def _hb_curve(ax, sub, color):
    """One HB branch: stable pieces solid, unstable dashed, folds as squares;
    a new piece starts at every point not joined to the one before it
    (:func:`~jointdyn.figures.curves.branch_pieces`, from ``point_status``)."""
    g = sub.gamma.to_numpy()
    a = sub.amplitude_q.to_numpy()
    st = sub.stable.to_numpy().astype(bool)
    for idx in branch_pieces(sub.point_status.to_numpy()):
        for run in _runs(st[idx]):
            j = idx[run[0]: run[-1] + 2] if run[-1] + 1 < idx.size else idx[run]
            ax.plot(g[j], a[j], "-", color=color, lw=1.4)
        for run in _runs(~st[idx]):
            j = idx[max(run[0] - 1, 0): run[-1] + 2]
            ax.plot(g[j], a[j], "--", color=color, lw=1.4)
    f = sub.fold.to_numpy().astype(bool)
    ax.plot(g[f], a[f], "ks", ms=5, mfc="none")


def _hb_legend(fig, betas, statuses, hb, td):
    """The betas, then an entry for each line style and marker that is drawn
    (unstable pieces, folds, time-domain points of either sweep)."""
    from matplotlib.lines import Line2D

    from .dynamics import BETA_COLORS

    h, lab = [], []
    for ib, beta in enumerate(betas):
        h.append(Line2D([], [], color=BETA_COLORS[ib % len(BETA_COLORS)], lw=1.4))
        lab.append(f"beta = {beta:g}" + (" (HB stopped: unbounded)" if statuses.get(beta) == "unbounded" else ""))
    drawn = [(not hb.stable.astype(bool).all(), Line2D([], [], color="k", ls="--"), "HB unstable (Hill)"),
             (hb.fold.astype(bool).any(), Line2D([], [], color="k", marker="s", mfc="none", ls="none"), "HB fold")]
    for d, mk in (("up", "^"), ("down", "v")):
        shown = td is not None and ((td.direction == d) & (td.status_name == "periodic")).any()
        drawn.append((shown, Line2D([], [], color="k", marker=mk, mfc="none", ls="none"),
                      f"time domain, sweep {d} (periodic points)"))
    for shown, handle, text in drawn:
        if shown:
            h.append(handle)
            lab.append(text)
    fig.legend(h, lab, loc="outside lower center", ncol=4, fontsize=8, frameon=False)


@fig6_hb.plotter
def _plot_fig6_hb(tables, out_dir):
    from .dynamics import BETA_COLORS, _linear_limits

    plt = pyplot()
    hb = tables["hb"]
    td = tables.get("time")
    etas = sorted(hb.eta.unique())
    betas = sorted(hb.beta.unique())
    fig, axes = plt.subplots(2, 2, figsize=(11, 9), sharex=True, layout="constrained")
    statuses = {}
    for ax, eta in zip(axes.ravel(), etas):
        for ib, beta in enumerate(betas):
            color = BETA_COLORS[ib % len(BETA_COLORS)]
            sub = hb[(hb.eta == eta) & (hb.beta == beta)].reset_index(drop=True)
            _hb_curve(ax, sub, color)
            if sub.status.iloc[0] == "unbounded":
                statuses[beta] = "unbounded"
            if td is not None:
                for d, mk in (("up", "^"), ("down", "v")):
                    t = td[(td.eta == eta) & (td.beta == beta) & (td.direction == d) & (td.status_name == "periodic")]
                    ax.plot(t.gamma, t.amplitude_q, mk, color=color, ms=4, alpha=0.7, mfc="none")
        ax.set_yscale("log")
        ax.set_title(f"eta = {eta:g}" + (" (separation)" if eta > 1 else " (contact)"), fontsize=10, pad=22)
        ax.grid(alpha=0.3, which="both")
        _linear_limits(ax)
    for ax in axes[1]:
        ax.set_xlabel("gamma = w / w0")
    for ax in axes[:, 0]:
        ax.set_ylabel("half peak-to-peak amplitude\nof q = kt x / fy")
    _hb_legend(fig, betas, statuses, hb, td)
    model = f"; {model_label(hb['model'].iloc[0])}" if "model" in hb else ""
    fig.suptitle("Paper Fig 6 cases by harmonic balance over time-domain steady states; eta varied by panel, "
                 f"beta by colour\n(H = 7, 128 samples per period, 512 for eta > 1; stability by Hill's method{model})",
                 fontsize=10)
    return save_figure(fig, out_dir, "fig6_hb")
