"""Quasi-static hysteresis loops: the paper's Figs 2-4 (and a ground-truth check).

- ``fig2``: the two kinds of Iwan loop at constant normal load (paper Fig 2):
  a small-amplitude loop in stick-slip (microslip) only and a
  large-amplitude loop that reaches macroslip, with the backbone.
  Figs 2-4 use the default contact law (``config.MODEL``, the exact Iwan
  model), which at constant load and in phase equals the paper's closed form.
- ``fig3``: paper Fig 3, kt = 100 kN/m, mu = 0.1, N0 = 100 N,
  x = 0.5 mm sin(2 pi t), N = N0 + eta N0 sin(2 pi t + delta), delta = 0,
  eta = 0, 0.3, 0.6, 0.9, 1.2 (1.2 separates: region S).
- ``fig4``: the same at delta = 90 deg (paper Fig 4).
- ``fig4_discrete``: the Fig 4 cases with the closed form (full Masing
  memory, ``iwan-closed``), the paper's last-reversal rule (``iwan-paper``)
  and the discrete ground truth (n = 1000 Jenkins elements) overlaid
  (docs/model.md sections 3 and 5): the paper's closed forms on purpose.

Two cycles are computed from the virgin state and the last (steady) one is
tabulated and plotted. Tables are long format (one row per sample).
"""

from __future__ import annotations


import numpy as np
import pandas as pd

from .. import config
from ..drivers import harmonic_loop
from ..laws import law_parameters, make_law
from ._registry import model_label, pyplot, register_figure, save_figure

#: paper section 2.2 (Figs 3-4)
PAPER_QS = dict(kt=1.0e5, mu=0.1, n0=100.0, amplitude=0.5e-3, frequency=1.0)
ETAS = (0.0, 0.3, 0.6, 0.9, 1.2)
_CYCLES = config.QS_CYCLES
_STEPS = config.QS_STEPS_PER_CYCLE
_N_DISCRETE = config.LAW_DISCRETE_N


def _legend_label(model) -> str:
    """The law's label (registered with the law), with n for the discrete model."""
    label = model_label(model)
    return f"{label}, n = {_N_DISCRETE}" if "n" in {q.name for q in law_parameters(model)} else label


def _law(model):
    p = PAPER_QS
    extra = {"n": _N_DISCRETE} if "n" in {q.name for q in law_parameters(model)} else {}
    return make_law(model, kt=p["kt"], mu=p["mu"], n_ref=p["n0"], **extra)


def _last_cycle(model, amplitude, eta, delta_deg):
    """Long table of the last cycle and a one-row metrics dict."""
    res = harmonic_loop(
        _law(model), amplitude, PAPER_QS["frequency"], PAPER_QS["n0"], eta=eta,
        delta_deg=delta_deg, cycles=_CYCLES, steps_per_cycle=_STEPS,
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


def _state_handles(loops, colors):
    """Legend entries for the state bands actually drawn: macroslip (a wide
    pale band in each loop's colour, one swatch per colour) and separation."""
    from matplotlib.legend_handler import HandlerTuple
    from matplotlib.lines import Line2D

    handles, labels, handler_map = [], [], {}
    states = set(loops["state"])
    if "macroslip" in states and colors:
        swatch = tuple(Line2D([], [], color=c, lw=4.4, alpha=0.25) for c in colors)
        handles.append(swatch)
        labels.append("macroslip (pale band)")
        handler_map[swatch] = HandlerTuple(ndivide=None, pad=0.0)
    if "separation" in states:
        handles.append(Line2D([], [], color="k", lw=5.4, alpha=0.35))
        labels.append("separation S (T = 0)")
    return handles, labels, handler_map


def _legend_below(fig, ax, loops, colors, ncol=3):
    """One legend under the axes (never over a loop): the curves of ``ax``
    and the state bands present in ``loops``."""
    h, lab = ax.get_legend_handles_labels()
    h2, lab2, handler_map = _state_handles(loops, colors)
    fig.legend(h + h2, lab + lab2, loc="outside lower center", ncol=ncol, fontsize=8, frameon=False,
               handler_map=handler_map)


# --------------------------------------------------------------------------
# Fig 2: the two kinds of Iwan loop
# --------------------------------------------------------------------------
#: small loop: A = 0.5 * 2 fy / kt (microslip only); large: the Fig 3 amplitude
FIG2_AMPLITUDES = (0.1e-3, 0.5e-3)


@register_figure("fig2", "Paper Fig 2: Iwan loops at constant normal load, amplitude varied (microslip only, with "
                 "macroslip); exact Iwan model", order=20)
def fig2():
    return _cases([config.MODEL], [0.0], 0.0, amplitudes=FIG2_AMPLITUDES)


def _branch_labels(x, st):
    """Sample index of the paper's Fig 2 labels on one steady loop: ``a`` at
    +A and ``c`` at -A; ``b`` and ``d`` where macroslip starts after ``a``
    and after ``c`` (a loop with macroslip) or, on a microslip-only loop,
    half-way along the unloading (x = -A/2) and loading (x = +A/2) branches."""
    pts = {"a": int(np.argmax(x)), "c": int(np.argmin(x))}
    n = x.size
    starts = sorted(r[0] for r in _runs(st == "macroslip"))
    half = 0.5 * (x.max() - x.min()) / 2
    for name, after, target in (("b", pts["a"], -half), ("d", pts["c"], half)):
        if starts:
            later = [i for i in starts if i > after] or starts
            pts[name] = later[0]
        else:  # first passage through x = target after the extreme
            order = (after + np.arange(n)) % n
            past = np.flatnonzero((x[order] - target) * np.sign(x[after]) <= 0)
            pts[name] = int(order[past[0]]) if past.size else after
    return pts


#: label offsets (points) that keep each Fig 2 label outside its loop
_LABEL_OFFSET = {"a": (6, -12), "b": (6, -12), "c": (6, 4), "d": (-16, 4)}


@fig2.plotter
def _plot_fig2(tables, out_dir):
    plt = pyplot()
    loops = tables["loops"]
    p = PAPER_QS
    fy = p["mu"] * p["n0"]
    fig, ax = plt.subplots(figsize=(6.8, 5.6), layout="constrained")
    colors = []
    for k, (A, g) in enumerate(loops.groupby("amplitude_m", sort=True)):
        g = g.reset_index(drop=True)
        kind = "microslip only" if A < 2 * fy / p["kt"] else "with macroslip"
        if (g["state"] == "macroslip").any():
            colors.append(f"C{k}")
        _draw_loop(ax, g, f"C{k}", f"A = {A * 1e3:g} mm ({kind})")
        x = g["x"].to_numpy() * 1e3
        T = g["T"].to_numpy()
        prime = "'" if kind == "with macroslip" else ""
        for lab, i in _branch_labels(x, g["state"].to_numpy()).items():
            ax.annotate(lab + prime, (x[i], T[i]), xytext=_LABEL_OFFSET[lab], textcoords="offset points",
                        fontsize=10, color=f"C{k}", fontweight="bold")
    xb = np.linspace(0.0, max(FIG2_AMPLITUDES), 201)
    q = p["kt"] * xb / fy
    ax.plot(xb * 1e3, fy * np.where(q < 2.0, q - q * q / 4.0, 1.0), color="0.35", ls=":", lw=1.4,
            label="backbone o-a (first loading from rest)")
    ax.plot([0.0], [0.0], "o", color="0.35", ms=4)
    ax.annotate("o", (0.0, 0.0), xytext=(-13, -3), textcoords="offset points", fontsize=10, color="0.35",
                fontweight="bold")
    ax.set_xlabel("tangential displacement x (mm)")
    ax.set_ylabel("tangential force T (N)")
    ax.set_title("Paper Fig 2: Iwan hysteresis loops at constant normal load, amplitude A varied\n"
                 f"kt = {p['kt'] / 1e3:g} kN/m, fy = {fy:g} N, x = A sin(2 pi t); steady cycle "
                 f"(last of {_CYCLES})\n{model_label(loops['model'].iloc[0])}", fontsize=10)
    ax.grid(True, alpha=0.3)
    _legend_below(fig, ax, loops, colors, ncol=2)
    return save_figure(fig, out_dir, "fig2", dpi=150)


# --------------------------------------------------------------------------
# Figs 3 and 4: varying normal load, in phase and out of phase
# --------------------------------------------------------------------------
_PHASE_WORDS = {0.0: "in phase", 90.0: "90 deg out of phase"}


def _plot_eta_family(tables, out_dir, name, delta_deg, paper_fig):
    plt = pyplot()
    loops = tables["loops"]
    fig, ax = plt.subplots(figsize=(6.8, 5.8), layout="constrained")
    colors = []
    for k, (eta, g) in enumerate(loops.groupby("eta", sort=True)):
        if (g["state"] == "macroslip").any():
            colors.append(f"C{k}")
        _draw_loop(ax, g.reset_index(drop=True), f"C{k}", f"eta = {eta:g}")
    p = PAPER_QS
    ax.set_xlabel("tangential displacement x (mm)")
    ax.set_ylabel("tangential force T (N)")
    phase = _PHASE_WORDS.get(float(delta_deg), f"delta = {delta_deg:g} deg")
    ax.set_title(
        f"Paper Fig {paper_fig}: normal load {phase} with the motion, eta = N1/N0 varied\n"
        f"x = {p['amplitude'] * 1e3:g} mm sin(2 pi t), N = N0 (1 + eta sin(2 pi t + delta)), "
        f"delta = {delta_deg:g} deg, N0 = {p['n0']:g} N\n{model_label(loops['model'].iloc[0])}", fontsize=9,
    )
    ax.grid(True, alpha=0.3)
    _legend_below(fig, ax, loops, colors, ncol=4)
    return save_figure(fig, out_dir, name, dpi=150)


@register_figure("fig3", "Paper Fig 3: loops, normal load in phase (delta = 0), eta = 0 ... 1.2 varied; exact Iwan "
                 "model", order=30)
def fig3():
    return _cases([config.MODEL], ETAS, 0.0)


@fig3.plotter
def _plot_fig3(tables, out_dir):
    return _plot_eta_family(tables, out_dir, "fig3", 0.0, 3)


@register_figure("fig4", "Paper Fig 4: loops, normal load 90 deg out of phase, eta = 0 ... 1.2 varied; exact Iwan "
                 "model", order=40)
def fig4():
    return _cases([config.MODEL], ETAS, 90.0)


@fig4.plotter
def _plot_fig4(tables, out_dir):
    return _plot_eta_family(tables, out_dir, "fig4", 90.0, 4)


@register_figure("fig4_discrete", "Paper Fig 4 cases, eta varied: the paper's closed forms (iwan-closed, iwan-paper) vs "
                 "the exact discrete Iwan model (n = 1000)", order=41)
def fig4_discrete():
    return _cases(["iwan-closed", "iwan-paper", "discrete"], ETAS, 90.0)


def _pct(value: float) -> str:
    """Signed percentage with two decimals; no sign on a value that rounds to 0."""
    text = f"{value:+.2f}"
    return ("0.00" if float(text) == 0.0 else text) + " %"


_DISCRETE_STYLE = {"discrete": ("0.15", "-", 2.6), "iwan-closed": ("C0", "-", 1.3), "iwan-paper": ("C3", "--", 1.3)}


def _energy_title(metrics, eta):
    """Panel title: eta and the energy per cycle of each closed form relative to the discrete model."""
    m = metrics[metrics["eta"] == eta].set_index("model")["energy_J"]
    parts = [f"eta = {eta:g}"]
    if "discrete" in m:
        for model, short in (("iwan-closed", "full memory"), ("iwan-paper", "paper rule")):
            if model in m:
                parts.append(f"{short}: {_pct(100 * (m[model] / m['discrete'] - 1))}")
    return "\n".join(parts)


@fig4_discrete.plotter
def _plot_fig4_discrete(tables, out_dir):
    plt = pyplot()
    loops = tables["loops"]
    metrics = tables["metrics"]
    fy = PAPER_QS["mu"] * PAPER_QS["n0"]
    etas = sorted(loops["eta"].unique())
    fig, axes = plt.subplots(2, len(etas), figsize=(3.3 * len(etas), 7.2), sharey="row", squeeze=False,
                             gridspec_kw={"height_ratios": [3, 2]}, layout="constrained")
    for j, eta in enumerate(etas):
        ax, axd = axes[0, j], axes[1, j]
        sub = loops[loops["eta"] == eta]
        ref = sub[sub["model"] == "discrete"].reset_index(drop=True)
        for model in ("discrete", "iwan-closed", "iwan-paper"):
            g = sub[sub["model"] == model].reset_index(drop=True)
            if g.empty:
                continue
            c, ls, lw = _DISCRETE_STYLE[model]
            _draw_loop(ax, g, c, _legend_label(model) if j == 0 else None, lw=lw, ls=ls,
                       mark_states=(model == "discrete"), macroslip=False)
            if model != "discrete" and not ref.empty:
                # same time grid for every model: compare sample by sample
                axd.plot(g["t"] - g["t"].iloc[0], (g["T"] - ref["T"]) / fy, color=c, ls=ls, lw=lw)
        ax.set_title(_energy_title(metrics, eta), fontsize=10)
        ax.set_xlabel("x (mm)", fontsize=10)
        axd.set_xlabel("t / period (steady cycle)", fontsize=10)
        for a in (ax, axd):
            a.grid(True, alpha=0.3)
            a.tick_params(labelsize=9)
    axes[0, 0].set_ylabel("T (N)", fontsize=10)
    axes[1, 0].set_ylabel("(T - T_discrete) / fy", fontsize=10)
    h, lab = axes[0, 0].get_legend_handles_labels()
    h2, lab2, hmap = _state_handles(loops[loops["model"] == "discrete"], [])
    fig.legend(h + h2, lab + lab2, loc="outside lower center", ncol=4, fontsize=10, frameon=False, handler_map=hmap)
    fig.suptitle("Paper Fig 4 cases (normal load 90 deg out of phase, eta varied): the paper's closed forms "
                 "(iwan-closed, iwan-paper) against the exact discrete Iwan model\npanel titles: energy per cycle "
                 "relative to the discrete model",
                 fontsize=11)
    return save_figure(fig, out_dir, "fig4_discrete", dpi=150)
