"""Figures of the forced friction damper (paper section 3-4, docs/model.md section 6).

``fig6``
    Frequency-response curves: normalised amplitude of q = kt x / fy vs
    gamma for eta = 0.01, 0.5, 1.5, 10 and beta from 0.1 to 1000, swept up
    and down (parallel sweep); points without a steady state are marked on
    a rug axis below each panel, never on the amplitude axis.
``fig7``
    Steady loops T vs x under a small tangential excitation with separation
    (eta > 1): the contact opens while it carries load (the force drops to
    zero at almost fixed x: a jump in the loop) or while it carries almost
    none (the loop stays continuous); which one depends on the phase of the
    normal load against the motion.
``fig8``
    Steady loops for delta from 0 to 180 deg, in contact (eta = 0.5) and with
    separation (eta = 1.5), with the exact Iwan model beside the paper's
    closed form (full memory, on purpose), and the energy per cycle of both
    against delta.
``energy_delta``
    Energy dissipated by the contact per cycle vs delta, in contact and with
    separation.

Every figure uses the default contact law (``config.MODEL``, the exact Iwan
model) except fig8's comparison panel, and names its model in its title.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from .. import config
from ._registry import model_label, pyplot, register_figure, save_figure
from .curves import RUG_MARKERS

#: Fig 6 grid (the paper's groups)
FIG6_ETAS = (0.01, 0.5, 1.5, 10.0)
FIG6_BETAS = (0.1, 1.0, 2.0, 5.0, 10.0, 1000.0)
FIG6_GAMMA = (0.6, 1.8, 0.01)
#: Figs 7, 8 and the energy-vs-delta study: forcing and frequency
FIG7_CASES = (
    # (label, eta, beta, gamma, delta_deg)
    ("a: opens while loaded (force jumps)", 1.5, 10.0, 0.8, 90.0),
    ("b: opens while unloaded (force continuous)", 1.5, 10.0, 0.8, 0.0),
)
FIG8_ETAS = (0.5, 1.5)
FIG8_BETA = 1.0
FIG8_GAMMA = 0.8
FIG8_DELTAS = (0.0, 45.0, 90.0, 135.0, 180.0)
ENERGY_DELTAS = tuple(float(d) for d in range(0, 181, 15))
ENERGY_BETAS = (1.0, 5.0)
ENERGY_GAMMAS = (0.8, 1.2, 1.6)


def _gamma_grid(spec):
    start, stop, step = spec
    return np.round(start + step * np.arange(int(round((stop - start) / step)) + 1), 12)


def fig6_data(gammas=None, etas=FIG6_ETAS, betas=FIG6_BETAS, **kw):
    """The Fig 6 sweep as a tidy table (one row per point, with the contact model's name)."""
    from ..sweeps import frc_sweep, to_frame

    g = _gamma_grid(FIG6_GAMMA) if gammas is None else gammas
    ds = frc_sweep(g, etas=etas, betas=betas, directions=("up", "down"), **kw)
    df = to_frame(ds)
    df["model"] = ds.attrs.get("model", "")
    return df[["eta", "beta", "direction", "gamma", "amplitude_q", "offset_m", "amplitude_m",
               "energy_contact_J", "periods", "status", "status_name", "model"]]


@register_figure("fig6", "Paper Fig 6: amplitude of q vs gamma; eta in {0.01, 0.5, 1.5, 10} by panel, beta 0.1..1000 "
                 "by colour; exact Iwan model", 60)
def fig6():
    return {"curves": fig6_data()}


#: one colour per beta, dark enough on white (ColorBrewer Dark2 without its yellow)
BETA_COLORS = ("#1b9e77", "#d95f02", "#7570b3", "#e7298a", "#66a61e", "#a6761d", "#666666")


def _status_names(codes):
    """Sweep status names of integer codes (:func:`jointdyn.sweeps.status_name`: the steady-state statuses,
    ``not-computed`` otherwise)."""
    from ..sweeps import status_name

    return np.array([status_name(c) for c in np.asarray(codes, int)])


def _linear_limits(ax):
    """Vertical lines at the two linear limits of the damper, labelled above the axes."""
    from ..systems import PAPER

    trans = ax.get_xaxis_transform()
    for g, text, ls in ((1.0, "gamma = 1\nall slipping", "-"),
                        (math.sqrt(1.0 + PAPER["kt"] / PAPER["k"]), "gamma = 1.33\nall stuck", ":")):
        ax.axvline(g, color="0.45", lw=0.8, ls=ls, zorder=0)
        ax.text(g, 1.01, text, transform=trans, ha="center", va="bottom", fontsize=7, color="0.3")


def _fig6_panel(ax, rug, df, betas):
    """Curves of one eta: sweep up as a wide pale band, sweep down as a thin
    line on top (where the two differ, the band and the line part); points
    without a steady state as markers on the rug axes below (one row per beta)."""
    for ib, beta in enumerate(betas):
        color = BETA_COLORS[ib % len(BETA_COLORS)]
        for d in ("up", "down"):
            sub = df[(df.beta == beta) & (df.direction == d)].sort_values("gamma")
            names = _status_names(sub.status)
            ok = names == "periodic"
            y = np.where(ok, sub.amplitude_q.to_numpy(), np.nan)
            if d == "up":
                ax.plot(sub.gamma, y, "-", color=color, lw=4.0, alpha=0.35, solid_capstyle="butt")
            else:
                ax.plot(sub.gamma, y, "-", color=color, lw=1.1, label=f"beta = {beta:g}")
            for name, (marker, face) in RUG_MARKERS.items():
                sel = names == name
                if sel.any():
                    rug.plot(sub.gamma[sel], np.full(sel.sum(), ib), marker, color=color, ms=5,
                             mfc=face if face else color, ls="none")
    ax.set_yscale("log")
    ax.grid(alpha=0.3, which="both")
    rug.set_ylim(-0.8, len(betas) - 0.2)
    rug.set_yticks([])
    rug.set_ylabel("no steady\nstate", fontsize=7, rotation=0, ha="right", va="center")
    rug.grid(alpha=0.3, axis="x")
    _linear_limits(ax)


def _fig6_legend(fig, ax, statuses):
    """The betas, the two sweeps, and the rug markers of the ``statuses`` that occur."""
    from matplotlib.lines import Line2D

    h, lab = ax.get_legend_handles_labels()
    h += [Line2D([], [], color="k", lw=4.0, alpha=0.35), Line2D([], [], color="k", lw=1.1)]
    lab += ["sweep up (pale band)", "sweep down (thin line)"]
    for name, (marker, face) in RUG_MARKERS.items():
        if name in statuses:
            h.append(Line2D([], [], color="k", marker=marker, mfc=face if face else "k", ls="none"))
            lab.append(f"{name.replace('-', ' ')} (rug)")
    fig.legend(h, lab, loc="outside lower center", ncol=6, fontsize=8, frameon=False)


@fig6.plotter
def _plot_fig6(tables, out_dir):
    plt = pyplot()
    df = tables["curves"]
    etas = sorted(df.eta.unique())
    betas = sorted(df.beta.unique())
    fig = plt.figure(figsize=(11, 9.5), layout="constrained")
    gs = fig.add_gridspec(4, 2, height_ratios=[7, 1.3, 7, 1.3])
    first = None
    for k, eta in enumerate(etas[:4]):
        r, c = divmod(k, 2)
        ax = fig.add_subplot(gs[2 * r, c], sharex=first)
        first = first or ax
        rug = fig.add_subplot(gs[2 * r + 1, c], sharex=first)
        _fig6_panel(ax, rug, df[df.eta == eta], betas)
        ax.set_title(f"eta = {eta:g}" + (" (separation)" if eta > 1 else " (contact)"), fontsize=10, pad=22)
        ax.tick_params(labelbottom=False)
        rug.set_xlabel("gamma = w / w0")
        ax.set_ylabel("half peak-to-peak amplitude\nof q = kt x / fy")
        if k == 0:
            _fig6_legend(fig, ax, set(_status_names(df.status)))
    model = f"; {model_label(df['model'].iloc[0])}" if "model" in df else ""
    fig.suptitle("Paper Fig 6: steady response vs frequency ratio gamma; eta = N1/N0 varied by panel, "
                 f"beta = mu N0 / F1 by colour (delta = 0{model})", fontsize=10)
    return save_figure(fig, out_dir, "fig6")


def steady_loop(eta, beta, gamma, delta_deg, *, model=config.MODEL, **kw):
    """One steady period (t, x, T, N, code) of the damper, or the solver's
    status when there is none.

    Returns
    -------
    (SteadyState, DataFrame)
        The result and its ``loop`` as a table (x in m, T and N in N).
    """
    from ..dynamics import steady_state
    from ..systems import System

    system = System.paper_damper(eta=eta, beta=beta, delta_deg=delta_deg, model=model)
    res = steady_state(system, gamma, keep_loop=True, **kw)
    lp = res.loop
    df = pd.DataFrame({
        "t": np.asarray(lp.t, float),
        "x": np.asarray(lp.x, float).reshape(len(lp.t), -1)[:, 0],
        "T": np.asarray(lp.T, float).reshape(len(lp.t), -1)[:, 0],
        "N": np.asarray(lp.N, float).reshape(len(lp.t), -1)[:, 0],
        "code": np.asarray(lp.code).reshape(len(lp.t), -1)[:, 0].astype(int),
    })
    return res, df


def _opening_run(code):
    """Indices around the first opening of a loop: ``(i, j)`` with ``i`` the
    last sample before separation (code 2) and ``j`` the start of the
    macroslip run (code 1) that leads into it (``j == i`` when there is
    none); None when the loop never opens. The loop is periodic: runs may
    wrap around its start."""
    code = np.asarray(code)
    n = code.size
    opens = np.flatnonzero((code == 2) & (np.roll(code, 1) != 2))
    if opens.size == 0:
        return None
    i = (opens[0] - 1) % n
    j = i
    for _ in range(n):
        if code[(j - 1) % n] != 1:
            break
        j = (j - 1) % n
    return int(i), int(j)


def _opening_drop(df):
    """How much load the contact carries when it starts to open.

    Before an opening (code 2) the falling normal load drags |T| down along
    the slip limit alpha fy (code 1, macroslip). Returns the force at the
    start of that last macroslip run (N) and the displacement travelled
    during it divided by the loop's half peak-to-peak amplitude: a large
    force lost over a small travel is the jump of Fig 7a; a force near 0 is
    the continuous case of Fig 7b. NaN when the loop has no opening.
    """
    run = _opening_run(df["code"].to_numpy())
    if run is None:
        return math.nan, math.nan
    i, j = run
    x = df["x"].to_numpy()
    T = df["T"].to_numpy()
    amp = 0.5 * (x.max() - x.min())
    return float(T[j]), float(abs(x[i] - x[j]) / amp) if amp > 0 else math.nan


def _loops(cases, model=config.MODEL):
    """Steady loops of ``cases`` ((label, eta, beta, gamma, delta_deg) each)
    with contact model ``model``: the loops as one long table and one row of
    results per case."""
    rows, info = [], []
    for label, eta, beta, gamma, delta in cases:
        res, df = steady_loop(eta, beta, gamma, delta, model=model)
        df.insert(0, "case", label)
        df.insert(1, "eta", eta)
        df.insert(2, "beta", beta)
        df.insert(3, "gamma", gamma)
        df.insert(4, "delta_deg", delta)
        rows.append(df)
        drop_T, drop_dx = _opening_drop(df)
        info.append(dict(case=label, model=model, eta=eta, beta=beta, gamma=gamma, delta_deg=delta, status=res.status,
                         amplitude_q=res.amplitude_q, energy_contact_J=res.energy_contact_J,
                         drop_T_N=drop_T, drop_dx_over_amp=drop_dx, periods=res.periods))
    return pd.concat(rows, ignore_index=True), pd.DataFrame(info)


@register_figure("fig7", "Paper Fig 7: loops under a small tangential load with separation, delta varied: force jump "
                 "vs continuous; exact Iwan model", 70)
def fig7():
    loops, info = _loops(FIG7_CASES)
    return {"loops": loops, "cases": info}


def _loop_axes(ax, df, label, color, ls="-", lw=1.2):
    x = df["x"].to_numpy() * 1e6
    T = df["T"].to_numpy()
    sep = df["code"].to_numpy() == 2
    ax.plot(np.r_[x, x[:1]], np.r_[T, T[:1]], color=color, lw=lw, ls=ls, label=label)
    if sep.any():
        ax.plot(x[sep], T[sep], ".", color=color, ms=2.5, alpha=0.6)


def _path_arrows(ax, x, T, color, count=8):
    """Arrows along a loop in the direction of time, evenly spaced in time."""
    n = x.size
    step = max(1, n // 200)
    for k in range(count):
        i = (k * n) // count
        j = (i + step) % n
        if (x[i], T[i]) != (x[j], T[j]):
            ax.annotate("", xy=(x[j], T[j]), xytext=(x[i], T[i]),
                        arrowprops=dict(arrowstyle="-|>", color=color, lw=1.2, mutation_scale=14))


def _label_opening(ax, df, color):
    """The paper's Fig 7 labels: A where the contact starts to lose its load
    on the way to opening, S on the separated stretch, B where contact returns."""
    x = df["x"].to_numpy() * 1e6
    T = df["T"].to_numpy()
    code = df["code"].to_numpy()
    run = _opening_run(code)
    if run is None:
        return
    i, j = run
    ax.plot([x[j]], [T[j]], "o", color="k", ms=4)
    ax.annotate("A", (x[j], T[j]), xytext=(6, 4), textcoords="offset points", fontsize=12, fontweight="bold")
    sep = np.flatnonzero(code == 2)
    mid = sep[sep.size // 2]
    ax.annotate("S", (x[mid], 0.0), xytext=(0, 8), textcoords="offset points", fontsize=12, fontweight="bold",
                ha="center")
    n = code.size
    back = [(k + 1) % n for k in sep if code[(k + 1) % n] != 2]
    if back:
        b = back[0]
        ax.plot([x[b]], [T[b]], "o", color="k", ms=4)
        ax.annotate("B", (x[b], T[b]), xytext=(-6, -14), textcoords="offset points", fontsize=12,
                    fontweight="bold", ha="right")


#: a force at A below this fraction of the loop's largest |T| is no jump: the contact opens unloaded
DROP_CONTINUOUS = 0.01


def _drop_text(force_N: float, travel: float, force_max_N: float) -> str:
    """What the contact carries at A and over how much travel it loses it, in
    words (``travel``: the displacement from A to the opening over the loop's
    half peak-to-peak amplitude, below 0.5 % a jump; ``force_max_N``: the
    loop's largest |T|, against which a force at A is nothing or a load)."""
    if not math.isfinite(force_N):
        return "the contact does not open"
    if abs(force_N) < DROP_CONTINUOUS * force_max_N:
        return f"T at A, where opening starts: {force_N:.3g} N, next to nothing: no force jump"
    where = (f"within {100 * travel:.0f} % of the amplitude" if travel >= 0.005 else
             "with no travel (a jump)")
    return f"T at A, where opening starts: {force_N:.3g} N, lost {where}"


@fig7.plotter
def _plot_fig7(tables, out_dir):
    plt = pyplot()

    loops, info = tables["loops"], tables["cases"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.0), layout="constrained")
    for ax, (_, row), tag in zip(axes, info.iterrows(), "ab"):
        df = loops[loops.case == row.case]
        _loop_axes(ax, df, None, "C0")
        _path_arrows(ax, df["x"].to_numpy() * 1e6, df["T"].to_numpy(), "C0")
        _label_opening(ax, df, "C0")
        ax.set_title(f"({tag}) delta = {row.delta_deg:g} deg: {row.case.split(': ', 1)[-1]}\n"
                     + _drop_text(row.drop_T_N, row.drop_dx_over_amp, float(df["T"].abs().max())), fontsize=9)
        ax.set_xlabel("tangential displacement x (um)")
        ax.set_ylabel("tangential force T (N)")
        ax.grid(alpha=0.3)
    row = info.iloc[0]
    fig.suptitle(f"Paper Fig 7: steady loops under a small tangential load with separation, phase delta varied "
                 f"(eta = {row.eta:g}, beta = {row.beta:g}, gamma = {row.gamma:g}; {model_label(row.model)})\n"
                 "arrows: direction of time; A: the contact starts to lose its load; S: separated (T = 0, dots); "
                 "B: contact returns", fontsize=9)
    return save_figure(fig, out_dir, "fig7")


#: Fig 8: the exact model beside the paper's closed form (full memory)
FIG8_MODELS = ((config.MODEL, model_label(config.MODEL), "exact"),
               ("iwan-closed", model_label("iwan-closed"), "closed form"))
#: phases of the energy-per-cycle panel (the loop panels show FIG8_DELTAS)
FIG8_ENERGY_DELTAS = tuple(float(d) for d in range(0, 181, 15))


@register_figure("fig8", "Paper Fig 8: steady loops for delta = 0..180 deg, in contact (eta 0.5) and with separation "
                 "(eta 1.5); exact Iwan model beside the paper's closed form, energy per cycle vs delta", 80)
def fig8():
    deltas = sorted(set(FIG8_DELTAS) | set(FIG8_ENERGY_DELTAS))
    loops, info = [], []
    for model, _, _ in FIG8_MODELS:
        cases = [(f"{model} eta {eta:g} delta {d:g}", eta, FIG8_BETA, FIG8_GAMMA, d) for eta in FIG8_ETAS
                 for d in deltas]
        lp, inf = _loops(cases, model=model)
        lp.insert(1, "model", model)
        keep = lp.delta_deg.isin(FIG8_DELTAS)  # loops drawn; every phase enters the energy panel
        loops.append(lp[keep])
        info.append(inf)
    return {"loops": pd.concat(loops, ignore_index=True), "cases": pd.concat(info, ignore_index=True)}


def _fig8_energy(ax, info, eta):
    """Energy dissipated by the contact per cycle vs delta, one curve per
    model, the largest loop of each starred and named in the title."""
    largest = []
    for k, (model, label, short) in enumerate(FIG8_MODELS):
        rows = info[(info.eta == eta) & (info.model == model)].sort_values("delta_deg")
        ok = rows.status == "periodic"
        ax.plot(rows.delta_deg, np.where(ok, rows.energy_contact_J * 1e3, np.nan), "-o" if k == 0 else "--s",
                color="k" if k == 0 else "C3", ms=3.5, mfc="none" if k else None, label=label)
        best = rows[ok].loc[rows[ok].energy_contact_J.idxmax()]
        ax.plot([best.delta_deg], [best.energy_contact_J * 1e3], "*", color="k" if k == 0 else "C3", ms=11)
        largest.append(f"{short} {best.delta_deg:g} deg")
    ax.set_xticks(range(0, 181, 45))
    ax.set_xlabel("delta (deg)")
    ax.set_ylabel("energy dissipated per cycle (mJ)")
    ax.set_title(f"loop area vs delta, eta = {eta:g}\nlargest (star): " + ", ".join(largest), fontsize=9)
    ax.grid(alpha=0.3)


@fig8.plotter
def _plot_fig8(tables, out_dir):
    plt = pyplot()

    loops, info = tables["loops"], tables["cases"]
    etas = sorted(info.eta.unique())
    fig, axes = plt.subplots(len(etas), 3, figsize=(15, 4.6 * len(etas)), squeeze=False, layout="constrained",
                             gridspec_kw={"width_ratios": [1, 1, 0.8]})
    cmap = plt.get_cmap("plasma")
    for r, eta in enumerate(etas):
        for c, (model, label, _) in enumerate(FIG8_MODELS):
            ax = axes[r, c]
            rows = info[(info.eta == eta) & (info.model == model) & info.delta_deg.isin(FIG8_DELTAS)]
            for i, (_, row) in enumerate(rows.sort_values("delta_deg").iterrows()):
                _loop_axes(ax, loops[loops.case == row.case], f"delta = {row.delta_deg:g} deg",
                           cmap(i / max(1, len(rows) - 1) * 0.85))
            ax.set_title(f"{label}: eta = {eta:g} ({'separation' if eta > 1 else 'contact'})", fontsize=9)
            ax.set_xlabel("x (um)")
            ax.set_ylabel("T (N)")
            ax.grid(alpha=0.3)
        _fig8_energy(axes[r, 2], info, eta)
    # one legend below the panels (the energy panels' curves are everywhere in
    # their axes, a legend inside would cover some): the phases, then the models
    h, lab = axes[0, 0].get_legend_handles_labels()
    h2, lab2 = axes[0, 2].get_legend_handles_labels()
    fig.legend(h + h2, lab + [f"energy (right): {t}" for t in lab2], loc="outside lower center",
               ncol=len(h + h2), fontsize=8, frameon=False)
    fig.suptitle(f"Paper Fig 8: steady loops, phase delta of the normal load varied (beta = {FIG8_BETA:g}, "
                 f"gamma = {FIG8_GAMMA:g}; dots: separated)\nThe paper finds the largest loop near delta = 90 deg "
                 "and the smallest at 0 and 180 deg: compare the largest loop (star) of the exact model and of the "
                 "closed form, right", fontsize=10)
    return save_figure(fig, out_dir, "fig8")


@register_figure("energy_delta", "Beyond paper Fig 8: energy dissipated per cycle vs delta, in contact and with "
                 "separation; exact Iwan model", 85)
def energy_delta():
    from ..sweeps import frc_sweep, to_frame

    ds = frc_sweep(list(ENERGY_GAMMAS), etas=FIG8_ETAS, betas=ENERGY_BETAS, deltas=ENERGY_DELTAS,
                   directions=("up",))
    df = to_frame(ds)
    df["model"] = ds.attrs.get("model", "")
    return {"energy": df[["eta", "beta", "delta", "gamma", "energy_contact_J", "work_force_J", "amplitude_q",
                          "offset_m", "status", "status_name", "model"]]}


@energy_delta.plotter
def _plot_energy(tables, out_dir):
    from matplotlib.lines import Line2D

    plt = pyplot()

    df = tables["energy"]
    etas = sorted(df.eta.unique())
    fig, axes = plt.subplots(1, len(etas), figsize=(5.6 * len(etas), 5.0), squeeze=False, layout="constrained")
    styles = ["-", "--", ":", "-."]
    for ax, eta in zip(axes[0], etas):
        sub_eta = df[df.eta == eta]
        betas = sorted(sub_eta.beta.unique())
        gammas = sorted(sub_eta.gamma.unique())
        for ib, beta in enumerate(betas):
            for ig, gamma in enumerate(gammas):
                sub = sub_eta[(sub_eta.beta == beta) & (sub_eta.gamma == gamma)].sort_values("delta")
                ok = (sub.status == 0).to_numpy()
                color = f"C{ig}"
                ax.plot(sub.delta, np.where(ok, sub.energy_contact_J, np.nan), marker="o", ms=3,
                        ls=styles[ib % 4], color=color, label=f"beta = {beta:g}, gamma = {gamma:g}")
                if (~ok).any():  # no steady state: an "x" on the bottom edge, never a number
                    ax.plot(sub.delta.to_numpy()[~ok], np.full((~ok).sum(), 0.0), "x", color=color, ms=8, mew=1.6,
                            transform=ax.get_xaxis_transform(), clip_on=False)
        ax.set_yscale("log")
        ax.set_xlabel("delta (deg)")
        ax.set_ylabel("energy dissipated by the contact per cycle (J)")
        ax.set_title(f"eta = {eta:g} ({'separation' if eta > 1 else 'contact'})", fontsize=10)
        ax.set_xticks(range(0, 181, 30))
        ax.grid(alpha=0.3, which="both")
    h, lab = axes[0, 0].get_legend_handles_labels()
    if (df.status != 0).any():  # the marker's entry only where one is drawn
        h.append(Line2D([], [], color="k", marker="x", ls="none", ms=8, mew=1.6))
        lab.append("no steady state (on the bottom edge)")
    fig.legend(h, lab, loc="outside lower center", ncol=4, fontsize=8, frameon=False)
    model = f"; {model_label(df['model'].iloc[0])}" if "model" in df else ""
    fig.suptitle("Beyond paper Fig 8: energy dissipated by the contact per cycle, phase delta of the normal load "
                 "varied,\nfor several forcing levels beta (line style) and frequencies gamma (colour) of the forced "
                 f"damper{model}", fontsize=10)
    return save_figure(fig, out_dir, "energy_delta")
