"""Quasi-static hysteresis loops: the paper's Figs 2-4 (and a ground-truth check).

- ``fig2``: the two kinds of Iwan loop at constant normal load (paper Fig 2):
  a small-amplitude loop in stick-slip (microslip) only and a
  large-amplitude loop that reaches macroslip, with the backbone.
- ``fig3``: paper Fig 3, kt = 100 kN/m, mu = 0.1, N0 = 100 N,
  x = 0.5 mm sin(2 pi t), N = N0 + eta N0 sin(2 pi t + delta), delta = 0,
  eta = 0, 0.3, 0.6, 0.9, 1.2 (1.2 separates: region S).
- ``fig4``: the same at delta = 90 deg (paper Fig 4).
- ``fig4_discrete``: the Fig 4 cases with the closed form (full Masing
  memory), the paper's last-reversal rule and the discrete ground truth
  (n = 1000 Jenkins elements) overlaid (MODEL.md sections 3 and 5).

Two cycles are computed from the virgin state and the last (steady) one is
tabulated and plotted. Tables are long format (one row per sample).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..drivers import harmonic_loop
from ..laws import law_parameters, make_law
from ._registry import pyplot, register_figure, save_figure

#: paper section 2.2 (Figs 3-4)
PAPER_QS = dict(kt=1.0e5, mu=0.1, n0=100.0, amplitude=0.5e-3, frequency=1.0)
ETAS = (0.0, 0.3, 0.6, 0.9, 1.2)
_CYCLES = 2
_STEPS = 2000
_N_DISCRETE = 1000
_MODEL_LABEL = {
    "iwan": "closed form (full memory)",
    "iwan-paper": "closed form (paper: last reversal)",
    "discrete": f"discrete, n = {_N_DISCRETE}",
}


def _law(model):
    p = PAPER_QS
    extra = {"n": _N_DISCRETE} if "n" in {q.name for q in law_parameters(model)} else {}
    return make_law(model, kt=p["kt"], mu=p["mu"], n_ref=p["n0"], **extra)


def _last_cycle(model, amplitude, eta, delta_deg):
    """Long table of the last cycle and a one-row metrics dict."""
    res = harmonic_loop(
        _law(model), amplitude, PAPER_QS["frequency"], PAPER_QS["n0"], eta=eta,
        delta=math.radians(delta_deg), cycles=_CYCLES, steps_per_cycle=_STEPS,
    )
    sl = res.cycle_slice(-1)
    df = pd.DataFrame(
        {
            "model": model,
            "eta": eta,
            "delta_deg": delta_deg,
            "amplitude_m": amplitude,
            "t": res.t[sl],
            "x": res.x[sl],
            "N": res.N[sl],
            "T": res.T[sl],
            "state": res.state[sl],
        }
    )
    m = {"model": model, "eta": eta, "delta_deg": delta_deg, "amplitude_m": amplitude, **res.last_cycle()}
    return df, m


def _cases(models, etas, delta_deg, amplitudes=(PAPER_QS["amplitude"],)):
    loops, metrics = [], []
    for model in models:
        for A in amplitudes:
            for eta in etas:
                df, m = _last_cycle(model, A, eta, delta_deg)
                loops.append(df)
                metrics.append(m)
    return {"loops": pd.concat(loops, ignore_index=True), "metrics": pd.DataFrame(metrics)}


# --------------------------------------------------------------------------
# drawing helpers (from the saved tables)
# --------------------------------------------------------------------------


def _runs(mask):
    """(start, stop) index pairs of the contiguous True runs of ``mask``."""
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        return []
    d = np.diff(np.concatenate(([0], m.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _draw_loop(ax, df, color, label, lw=1.4, ls="-", mark_states=True, macroslip=True):
    x = df["x"].to_numpy() * 1e3
    T = df["T"].to_numpy()
    st = df["state"].to_numpy()
    ax.plot(x, T, color=color, lw=lw, ls=ls, label=label)
    if not mark_states:
        return
    for a, b in _runs(st == "macroslip") if macroslip else []:
        ax.plot(x[a:b], T[a:b], color=color, lw=lw + 3.0, alpha=0.25, solid_capstyle="butt")
    for a, b in _runs(st == "separation"):
        ax.plot(x[a:b], T[a:b], color="k", lw=lw + 4.0, alpha=0.35, solid_capstyle="butt")
        i = (a + b) // 2
        ax.annotate("S", (x[i], T[i]), xytext=(0, 8), textcoords="offset points", ha="center", fontsize=10)


def _state_legend(ax):
    from matplotlib.lines import Line2D

    h, lab = ax.get_legend_handles_labels()
    h += [
        Line2D([], [], color="0.4", lw=4.4, alpha=0.25),
        Line2D([], [], color="k", lw=5.4, alpha=0.35),
    ]
    lab += ["macroslip (wide band)", "separation S (T = 0)"]
    ax.legend(h, lab, fontsize=7, loc="upper left")


# --------------------------------------------------------------------------
# Fig 2: the two kinds of Iwan loop
# --------------------------------------------------------------------------
#: small loop: A = 0.5 * 2 fy / kt (microslip only); large: the Fig 3 amplitude
FIG2_AMPLITUDES = (0.1e-3, 0.5e-3)


@register_figure("fig2", "Iwan hysteresis loops at constant normal load: microslip only and with macroslip", order=20)
def fig2():
    return _cases(["iwan"], [0.0], 0.0, amplitudes=FIG2_AMPLITUDES)


@fig2.plotter
def _plot_fig2(tables, out_dir):
    plt = pyplot()
    loops = tables["loops"]
    p = PAPER_QS
    fy = p["mu"] * p["n0"]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for k, (A, g) in enumerate(loops.groupby("amplitude_m", sort=True)):
        g = g.reset_index(drop=True)
        kind = "microslip only" if A < 2 * fy / p["kt"] else "with macroslip"
        _draw_loop(ax, g, f"C{k}", f"A = {A * 1e3:g} mm ({kind})")
        # paper's labels: a at +A, c at -A; b / d where macroslip starts
        x = g["x"].to_numpy() * 1e3
        T = g["T"].to_numpy()
        st = g["state"].to_numpy()
        prime = "'" if kind == "with macroslip" else ""
        pts = {"a": int(np.argmax(x)), "c": int(np.argmin(x))}
        runs = _runs(st == "macroslip")
        if runs:
            # order the macroslip starts after a (unloading) then after c (loading)
            starts = sorted(r[0] for r in runs)
            after_a = [s for s in starts if s > pts["a"]] or starts
            after_c = [s for s in starts if s > pts["c"]] or starts
            pts["b"] = after_a[0]
            pts["d"] = after_c[0]
        for lab, i in pts.items():
            ax.annotate(lab + prime, (x[i], T[i]), xytext=(4, 4), textcoords="offset points", fontsize=9,
                        color=f"C{k}")
    xb = np.linspace(-max(FIG2_AMPLITUDES), max(FIG2_AMPLITUDES), 401)
    q = np.abs(p["kt"] * xb / fy)
    Tb = np.sign(xb) * fy * np.where(q < 2.0, q - q * q / 4.0, 1.0)
    ax.plot(xb * 1e3, Tb, color="0.5", ls=":", lw=1.0, label="backbone oa")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("T (N)")
    ax.set_title(f"Iwan loops, kt = {p['kt'] / 1e3:g} kN/m, fy = {fy:g} N (last of {_CYCLES} cycles)", fontsize=9)
    ax.grid(True, alpha=0.3)
    _state_legend(ax)
    fig.tight_layout()
    return save_figure(fig, out_dir, "fig2", dpi=150)


# --------------------------------------------------------------------------
# Figs 3 and 4: varying normal load, in phase and out of phase
# --------------------------------------------------------------------------
def _plot_eta_family(tables, out_dir, name, delta_deg):
    plt = pyplot()
    loops = tables["loops"]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    for k, (eta, g) in enumerate(loops.groupby("eta", sort=True)):
        _draw_loop(ax, g.reset_index(drop=True), f"C{k}", f"eta = {eta:g}")
    p = PAPER_QS
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("T (N)")
    ax.set_title(
        f"x = {p['amplitude'] * 1e3:g} mm sin(2 pi t), N = N0 (1 + eta sin(2 pi t + {delta_deg:g} deg)), "
        f"N0 = {p['n0']:g} N", fontsize=8,
    )
    ax.grid(True, alpha=0.3)
    _state_legend(ax)
    fig.tight_layout()
    return save_figure(fig, out_dir, name, dpi=150)


@register_figure("fig3", "Loops under in-phase normal load (delta = 0), eta = 0 ... 1.2 (paper Fig 3)", order=30)
def fig3():
    return _cases(["iwan"], ETAS, 0.0)


@fig3.plotter
def _plot_fig3(tables, out_dir):
    return _plot_eta_family(tables, out_dir, "fig3", 0.0)


@register_figure("fig4", "Loops under out-of-phase normal load (delta = 90 deg), eta = 0 ... 1.2 (paper Fig 4)", order=40)
def fig4():
    return _cases(["iwan"], ETAS, 90.0)


@fig4.plotter
def _plot_fig4(tables, out_dir):
    return _plot_eta_family(tables, out_dir, "fig4", 90.0)


@register_figure("fig4_discrete", "Fig 4 cases: closed forms vs discrete Iwan (n = 1000) ground truth", order=41)
def fig4_discrete():
    return _cases(["iwan", "iwan-paper", "discrete"], ETAS, 90.0)


@fig4_discrete.plotter
def _plot_fig4_discrete(tables, out_dir):
    plt = pyplot()
    loops = tables["loops"]
    metrics = tables["metrics"]
    fy = PAPER_QS["mu"] * PAPER_QS["n0"]
    etas = sorted(loops["eta"].unique())
    fig, axes = plt.subplots(2, len(etas), figsize=(3.0 * len(etas), 5.6), sharey="row",
                             gridspec_kw={"height_ratios": [3, 2]})
    axes = np.asarray(axes).reshape(2, len(etas))
    style = {"discrete": ("0.2", "-", 2.4), "iwan": ("C0", "-", 1.1), "iwan-paper": ("C3", "--", 1.1)}
    for j, eta in enumerate(etas):
        ax, axd = axes[0, j], axes[1, j]
        sub = loops[loops["eta"] == eta]
        ref = sub[sub["model"] == "discrete"].reset_index(drop=True)
        for model in ("discrete", "iwan", "iwan-paper"):
            g = sub[sub["model"] == model].reset_index(drop=True)
            if g.empty:
                continue
            c, ls, lw = style[model]
            _draw_loop(ax, g, c, _MODEL_LABEL[model], lw=lw, ls=ls, mark_states=(model == "discrete"),
                       macroslip=False)
            if model != "discrete" and not ref.empty:
                # same time grid for every model: compare sample by sample
                axd.plot(g["t"] - g["t"].iloc[0], (g["T"] - ref["T"]) / fy, color=c, ls=ls, lw=lw,
                         label=_MODEL_LABEL[model])
        m = metrics[metrics["eta"] == eta].set_index("model")["energy_per_cycle_J"]
        parts = [f"eta = {eta:g}"]
        if "discrete" in m:
            for model, short in (("iwan", "full"), ("iwan-paper", "paper")):
                if model in m:
                    parts.append(f"{short} {100 * (m[model] / m['discrete'] - 1):+.2f}%")
        ax.set_title(", ".join(parts), fontsize=8)
        ax.set_xlabel("x (mm)")
        ax.grid(True, alpha=0.3)
        axd.set_xlabel("t / period (last cycle)")
        axd.grid(True, alpha=0.3)
    axes[0, 0].set_ylabel("T (N)")
    axes[1, 0].set_ylabel("(T - T_discrete) / fy")
    axes[0, 0].legend(fontsize=6, loc="upper left")
    fig.suptitle("delta = 90 deg: closed forms vs discrete ground truth (titles: energy per cycle relative "
                 "to discrete; S: separation)", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, out_dir, "fig4_discrete", dpi=150)
