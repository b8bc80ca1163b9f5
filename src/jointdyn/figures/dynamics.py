"""Figures of the forced friction damper (paper section 3-4, MODEL.md section 6).

``fig6``
    Frequency-response curves: normalised amplitude of q = kt x / fy vs
    gamma for eta = 0.01, 0.5, 1.5, 10 and beta from 0.1 to 1000, swept up
    and down (parallel sweep); points without a steady state are marked.
``fig7``
    Steady loops T vs x under a small tangential excitation with separation
    (eta > 1): the contact opens while it carries load (the force drops to
    zero at almost fixed x: a jump in the loop) or while it carries almost
    none (the loop stays continuous); which one depends on the phase of the
    normal load against the motion.
``fig8``
    Steady loops for delta from 0 to 180 deg, in contact (eta = 0.5) and with
    separation (eta = 1.5).
``energy_delta``
    Energy dissipated by the contact per cycle vs delta, in contact and with
    separation.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._registry import pyplot, register_figure, save_figure

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
    """The Fig 6 sweep as a tidy table (one row per point)."""
    from ..sweeps import frc_sweep, to_frame

    g = _gamma_grid(FIG6_GAMMA) if gammas is None else gammas
    ds = frc_sweep(g, etas=etas, betas=betas, directions=("up", "down"), **kw)
    df = to_frame(ds)
    return df[["eta", "beta", "direction", "gamma", "amplitude_q", "offset_m", "amplitude_m",
               "energy_contact_J", "periods", "status", "status_name"]]


@register_figure("fig6", "Frequency response: amplitude of q vs gamma for eta in {0.01, 0.5, 1.5, 10}, beta 0.1..1000", 60)
def fig6():
    return {"curves": fig6_data()}


@fig6.plotter
def _plot_fig6(tables, out_dir):
    plt = pyplot()

    from ..sweeps._plot import mark_legend, plot_frc_curve

    df = tables["curves"]
    etas = sorted(df.eta.unique())
    betas = sorted(df.beta.unique())
    cmap = plt.get_cmap("viridis")
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), sharex=True)
    for ax, eta in zip(axes.ravel(), etas):
        for ib, beta in enumerate(betas):
            color = cmap(ib / max(1, len(betas) - 1))
            for d, style in (("up", "-"), ("down", "--")):
                sub = df[(df.eta == eta) & (df.beta == beta) & (df.direction == d)].sort_values("gamma")
                plot_frc_curve(ax, sub.gamma, sub.amplitude_q, sub.status, color=color, linestyle=style,
                               label=f"beta = {beta:g}" if d == "up" else None,
                               rug_y=0.02 + 0.025 * ib)
        ax.set_yscale("log")
        lo, hi = ax.get_ylim()  # free the bottom quarter for the rug markers
        ax.set_ylim(lo / (hi / lo) ** 0.3, hi)
        ax.set_title(f"eta = {eta:g}" + (" (separation)" if eta > 1 else ""), fontsize=10)
        ax.axvline(1.0, color="0.7", lw=0.6)
        ax.axvline(math.sqrt(1 + 3e5 / 3.9e5), color="0.7", lw=0.6, ls=":")
        ax.grid(alpha=0.3, which="both")
    for ax in axes[1]:
        ax.set_xlabel("gamma = w / w0")
    for ax in axes[:, 0]:
        ax.set_ylabel("amplitude of q = kt x / fy")
    mark_legend(axes[0, 0], fontsize=7, ncol=8)
    leg = axes[0, 0].get_legend()
    handles, labels = leg.legend_handles, [t.get_text() for t in leg.get_texts()]
    leg.remove()
    fig.legend(handles, labels, loc="lower center", ncol=8, fontsize=7, frameon=False)
    fig.suptitle("Fig 6: steady response, sweep up (solid) and down (dashed); markers at the bottom: "
                 "no steady state (x unbounded, o not settled)", fontsize=9)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    return save_figure(fig, out_dir, "fig6")


def steady_loop(eta, beta, gamma, delta_deg, *, model="iwan", **kw):
    """One steady period (t, x, T, N, code) of the damper, or the solver's
    status when there is none.

    Returns
    -------
    (SteadyState, DataFrame)
        The result and its ``loop`` as a table (x in m, T and N in N).
    """
    from ..dynamics import steady_state
    from ..systems import System

    system = System.paper_damper(eta=eta, beta=beta, delta=math.radians(delta_deg), model=model)
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


def _opening_drop(df):
    """How much load the contact carries when it starts to open.

    Before an opening (code 2) the falling normal load drags |T| down along
    the slip limit alpha fy (code 1, macroslip). Returns the force at the
    start of that last macroslip run (N) and the displacement travelled
    during it divided by the loop's half peak-to-peak amplitude: a large
    force lost over a small travel is the jump of Fig 7a; a force near 0 is
    the continuous case of Fig 7b. NaN when the loop has no opening.
    """
    code = df["code"].to_numpy()
    x = df["x"].to_numpy()
    T = df["T"].to_numpy()
    n = code.size
    opens = np.flatnonzero((code == 2) & (np.roll(code, 1) != 2))
    if opens.size == 0:
        return math.nan, math.nan
    i = (opens[0] - 1) % n
    j = i
    for _ in range(n):
        if code[(j - 1) % n] != 1:
            break
        j = (j - 1) % n
    amp = 0.5 * (x.max() - x.min())
    return float(T[j]), float(abs(x[i] - x[j]) / amp) if amp > 0 else math.nan


def _loops(cases):
    rows, info = [], []
    for label, eta, beta, gamma, delta in cases:
        res, df = steady_loop(eta, beta, gamma, delta)
        df.insert(0, "case", label)
        df.insert(1, "eta", eta)
        df.insert(2, "beta", beta)
        df.insert(3, "gamma", gamma)
        df.insert(4, "delta_deg", delta)
        rows.append(df)
        drop_T, drop_dx = _opening_drop(df)
        info.append(dict(case=label, eta=eta, beta=beta, gamma=gamma, delta_deg=delta, status=res.status,
                         amplitude_q=res.amplitude_q, energy_contact_J=res.energy_contact_J,
                         drop_T_N=drop_T, drop_dx_over_amp=drop_dx, periods=res.periods))
    return pd.concat(rows, ignore_index=True), pd.DataFrame(info)


@register_figure("fig7", "Loops under a small tangential excitation with separation: force jump vs continuous", 70)
def fig7():
    loops, info = _loops(FIG7_CASES)
    return {"loops": loops, "cases": info}


def _loop_axes(ax, df, label, color):
    x = df["x"].to_numpy() * 1e6
    T = df["T"].to_numpy()
    sep = df["code"].to_numpy() == 2
    ax.plot(np.r_[x, x[:1]], np.r_[T, T[:1]], color=color, lw=1.2, label=label)
    if sep.any():
        ax.plot(x[sep], T[sep], ".", color=color, ms=2.5, alpha=0.6)


@fig7.plotter
def _plot_fig7(tables, out_dir):
    plt = pyplot()

    loops, info = tables["loops"], tables["cases"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, (_, row) in zip(axes, info.iterrows()):
        df = loops[loops.case == row.case]
        _loop_axes(ax, df, "loop (dots: separated, T = 0)", "C0")
        ax.set_title(f"{row.case}\neta = {row.eta:g}, beta = {row.beta:g}, gamma = {row.gamma:g}, "
                     f"delta = {row.delta_deg:g} deg\nload when opening starts = {row.drop_T_N:.3g} N, lost over "
                     f"{row.drop_dx_over_amp:.2g} of the amplitude", fontsize=8)
        ax.set_xlabel("x (um)")
        ax.set_ylabel("T (N)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Fig 7: separation under a small tangential load. (a) the contact opens while it carries "
                 "tangential load, so T falls to 0 at almost fixed x; (b) it opens near T = 0", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, out_dir, "fig7")


@register_figure("fig8", "Steady loops for delta = 0..180 deg, in contact (eta 0.5) and with separation (eta 1.5)", 80)
def fig8():
    cases = [(f"eta {eta:g} delta {d:g}", eta, FIG8_BETA, FIG8_GAMMA, d) for eta in FIG8_ETAS for d in FIG8_DELTAS]
    loops, info = _loops(cases)
    return {"loops": loops, "cases": info}


@fig8.plotter
def _plot_fig8(tables, out_dir):
    plt = pyplot()

    loops, info = tables["loops"], tables["cases"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    cmap = plt.get_cmap("plasma")
    for ax, eta in zip(axes, sorted(info.eta.unique())):
        rows = info[info.eta == eta].sort_values("delta_deg")
        for i, (_, row) in enumerate(rows.iterrows()):
            df = loops[loops.case == row.case]
            _loop_axes(ax, df, f"delta = {row.delta_deg:g} deg, E = {row.energy_contact_J:.3g} J",
                       cmap(i / max(1, len(rows) - 1) * 0.9))
        ax.set_title(f"eta = {eta:g} ({'separation' if eta > 1 else 'contact'}), beta = {FIG8_BETA:g}, "
                     f"gamma = {FIG8_GAMMA:g}", fontsize=9)
        ax.set_xlabel("x (um)")
        ax.set_ylabel("T (N)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Fig 8: steady hysteresis loops vs phase delta of the normal load (dots: separated)", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, out_dir, "fig8")


@register_figure("energy_delta", "Energy dissipated per cycle vs delta, in contact and with separation", 85)
def energy_delta():
    from ..sweeps import frc_sweep, to_frame

    ds = frc_sweep(list(ENERGY_GAMMAS), etas=FIG8_ETAS, betas=ENERGY_BETAS, deltas=ENERGY_DELTAS,
                   directions=("up",))
    df = to_frame(ds)
    return {"energy": df[["eta", "beta", "delta", "gamma", "energy_contact_J", "work_force_J", "amplitude_q",
                          "offset_m", "status", "status_name"]]}


@energy_delta.plotter
def _plot_energy(tables, out_dir):
    plt = pyplot()

    df = tables["energy"]
    etas = sorted(df.eta.unique())
    fig, axes = plt.subplots(1, len(etas), figsize=(5.2 * len(etas), 4.2), squeeze=False)
    styles = ["-", "--", ":", "-."]
    for ax, eta in zip(axes[0], etas):
        sub_eta = df[df.eta == eta]
        betas = sorted(sub_eta.beta.unique())
        gammas = sorted(sub_eta.gamma.unique())
        for ib, beta in enumerate(betas):
            for ig, gamma in enumerate(gammas):
                sub = sub_eta[(sub_eta.beta == beta) & (sub_eta.gamma == gamma)].sort_values("delta")
                ok = sub.status == 0
                color = f"C{ig}"
                ax.plot(sub.delta, np.where(ok, sub.energy_contact_J, np.nan), marker="o", ms=3, ls=styles[ib % 4],
                        color=color,
                        label=f"beta = {beta:g}, gamma = {gamma:g}")
                if (~ok).any():
                    ax.plot(sub.delta[~ok], np.full((~ok).sum(), 0.03), "x", color=color,
                            transform=ax.get_xaxis_transform())
        ax.set_yscale("log")
        ax.set_xlabel("delta (deg)")
        ax.set_ylabel("energy dissipated by the contact per cycle (J)")
        ax.set_title(f"eta = {eta:g} ({'separation' if eta > 1 else 'contact'}); x: no steady state", fontsize=9)
        ax.set_xticks(range(0, 181, 30))
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("Contact dissipation per cycle vs the phase delta of the normal load (forced damper)", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, out_dir, "energy_delta")
