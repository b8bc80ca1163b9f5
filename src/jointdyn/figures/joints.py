"""Figures of joints whose normal load comes from the structure (time domain).

``normal_dof``
    The paper's damper with its normal spring (kn = 3e5 N/m) carrying the
    load from a normal DOF driven by a normal force eta N0 sin(w t + delta),
    against the paper's prescribed load of the same amplitude. A light
    normal DOF (normal natural frequency sqrt(kn / m_n) = 27.7 w0) responds
    quasi-statically and reproduces the prescribed load; a heavy one (2 w0)
    amplifies the normal-load oscillation near the tangential resonance and
    changes the response.
``blade_damper``
    A three-DOF blade (platform, mid-span, tip) with a wedge damper under its
    platform in the spirit of Yang and Menq: the platform's motion at 45
    degrees to the contact plane slides the contact and, at the same time,
    compresses or relieves the damper's normal spring (preload P from the
    centrifugal load), so the normal load follows the blade's motion and the
    contact can open. Response curves of the tip for several preloads and the
    design chart engineers draw, the peak tip amplitude against the preload
    with its optimum, beside the two linear references (the blade without
    its damper, and the damper stuck with its spring closed).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ._registry import pyplot, register_figure, save_figure

#: normal-DOF showcase: the paper damper's groups and the normal DOF's masses
NORMAL_DOF_CASE = {"eta": 0.5, "beta": 2.0, "delta_deg": 0.0}
NORMAL_DOF_GAMMAS = (0.6, 1.8, 0.01)
#: normal natural frequency sqrt(kn / m_n) of the heavy normal DOF, in units of w0
HEAVY_NORMAL_RATIO = 2.0

#: blade: masses (kg) and chain stiffnesses ground-platform, platform-mid,
#: mid-tip (N/m); wedge angle (deg); damper contact (N/m, -, N/m); tip force (N)
BLADE = {"m": (0.3, 0.5, 0.5), "k": (1e5, 2e5, 2e5), "theta_deg": 45.0, "kt": 3e5, "mu": 0.5, "kn": 3e5,
         "force_N": 2.0, "zeta": 0.005}
BLADE_GAMMAS = (0.8, 1.3, 0.005)
#: preloads of the design chart (N); the response curves show every other one
BLADE_PRELOADS = (0.3, 1.0, 3.0, 6.0, 10.0, 15.0, 20.0, 30.0, 50.0, 100.0, 300.0, 1000.0)
BLADE_CURVES = (0.3, 3.0, 10.0, 30.0, 100.0, 1000.0)


def _grid(spec) -> np.ndarray:
    lo, hi, step = spec
    return np.round(lo + step * np.arange(int(round((hi - lo) / step)) + 1), 10)


def _curve_rows(ds, labels: dict) -> pd.DataFrame:
    """One row per (system, direction, gamma) of a sweep Dataset of labelled Systems."""
    from ..sweeps import status_name

    rows = []
    for name, extra in labels.items():
        for direction in ds.direction.values:
            one = ds.sel(system=name, direction=direction)
            rows.append(pd.DataFrame({
                **extra,
                "direction": str(direction),
                "gamma": one.gamma.values,
                "amplitude_m": one.amplitude_m.values,
                "status": [status_name(c) for c in one.status.values],
                "negative_dissipation": one.negative_dissipation.values.astype(int),
            }))
    return pd.concat(rows, ignore_index=True)


def normal_dof_data():
    """Response curves of the paper damper: prescribed load, light and heavy normal DOF."""
    from ..sweeps import frc_sweep
    from ..systems import PAPER, System

    w0 = float(np.sqrt(PAPER["k"] / PAPER["m"]))
    heavy = PAPER["kn"] / (HEAVY_NORMAL_RATIO * w0) ** 2
    systems = {
        "prescribed": System.paper_damper(**NORMAL_DOF_CASE),
        "spring, light normal DOF": System.paper_damper(**NORMAL_DOF_CASE, normal="spring"),
        "spring, heavy normal DOF": System.paper_damper(**NORMAL_DOF_CASE, normal="spring", normal_mass=heavy),
    }
    ds = frc_sweep(systems, _grid(NORMAL_DOF_GAMMAS), directions=("up",), dofs=[0], progress=False)
    fy = PAPER["mu"] * PAPER["n0"]
    df = _curve_rows(ds, {k: {"case": k} for k in systems})
    df["amplitude_q"] = df.amplitude_m * PAPER["kt"] / fy
    df["normal_mass_kg"] = df.case.map({k: (s.M[1, 1] if s.ndof > 1 else 0.0) for k, s in systems.items()})
    return {"curves": df}


@register_figure("normal_dof", "The paper's damper with its normal spring on a normal DOF against the prescribed "
                 "load: where they agree and where normal dynamics change the answer", 90)
def normal_dof():
    return normal_dof_data()


@normal_dof.plotter
def _plot_normal_dof(tables, out_dir):
    plt = pyplot()
    df = tables["curves"]
    fig, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
    style = {"prescribed": ("k", "-", 2.4), "spring, light normal DOF": ("C0", "--", 1.6),
             "spring, heavy normal DOF": ("C3", "-", 1.6)}
    for case, sub in df.groupby("case", sort=False):
        color, ls, lw = style.get(case, ("0.5", "-", 1.0))
        ok = sub.status == "periodic"
        q = sub.amplitude_q.where(ok)  # a point that is not periodic is a break, not a line
        ax.plot(sub.gamma, q, ls, color=color, lw=lw, label=f"{case}" + (
            f" (m_n = {sub.normal_mass_kg.iloc[0]:.3g} kg)" if sub.normal_mass_kg.iloc[0] > 0 else ""))
        bad = sub[~ok]
        if len(bad):
            ax.plot(bad.gamma, np.zeros(len(bad)), "x", color=color, ms=5, label=f"{case}: not periodic")
    c = NORMAL_DOF_CASE
    ax.set_xlabel("gamma = w / w0")
    ax.set_ylabel("q = kt X / fy")
    ax.set_title(f"Normal load from a normal DOF (kn = 3e5 N/m) vs prescribed: eta = {c['eta']:g}, "
                 f"beta = {c['beta']:g}, delta = {c['delta_deg']:g} deg", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, out_dir, "normal_dof")


def blade_system(preload: float, model: str | None = None):
    """The blade with its wedge damper at preload ``preload`` (N): a :class:`~jointdyn.System`."""
    from .. import config
    from ..kinematics import NormalSpring
    from ..laws import make_law
    from ..systems import Contact, System, modal_damping

    b = BLADE
    k0, k1, k2 = b["k"]
    K = np.array([[k0 + k1, -k1, 0.0], [-k1, k1 + k2, -k2], [0.0, -k2, k2]])
    M = np.diag(b["m"])
    th = np.radians(b["theta_deg"])
    tangential = np.array([np.cos(th), 0.0, 0.0])
    normal = np.array([np.sin(th), 0.0, 0.0])
    law = make_law(model or config.MODEL, kt=b["kt"], mu=b["mu"], n_ref=preload)
    contact = Contact(law, direction=tangential, normal=NormalSpring(kn=b["kn"], preload=preload, direction=normal))
    C = modal_damping(M, K + b["kn"] * np.outer(normal, normal), b["zeta"])
    return System(M, C, K, contacts=(contact,), force=[0.0, 0.0, b["force_N"]], output_dof=2)


def _linear_peak(system, K) -> tuple[float, float]:
    """Peak tip amplitude (m) and its gamma of the linear FRF with stiffness K
    (the peak of its lowest mode, on a fine grid around that mode)."""
    import scipy.linalg as sl

    w1 = float(np.sqrt(sl.eigh(K, system.M, eigvals_only=True)[0])) / system.w0
    g = np.linspace(0.9 * w1, 1.1 * w1, 20001)
    amp = np.array([abs(np.linalg.solve(K - (x * system.w0) ** 2 * system.M + 1j * x * system.w0 * system.C,
                                        system.force.astype(complex))[system.response_dof]) for x in g])
    i = int(np.argmax(amp))
    return float(amp[i]), float(g[i])


def blade_data():
    """Tip response curves for each preload, the design chart and the two linear limits."""
    from ..sweeps import frc_sweep

    gammas = _grid(BLADE_GAMMAS)
    systems = {f"P = {p:g} N": blade_system(p) for p in BLADE_PRELOADS}
    ds = frc_sweep(systems, gammas, directions=("up", "down"), dofs=[2], progress=False)
    curves = _curve_rows(ds, {f"P = {p:g} N": {"preload_N": p} for p in BLADE_PRELOADS})
    rows = []
    for p, sub in curves.groupby("preload_N"):  # the peak of either sweep: jumps make them differ
        ok = sub[sub.status == "periodic"]
        i = ok.amplitude_m.idxmax()
        rows.append({"preload_N": p, "peak_m": ok.amplitude_m[i], "gamma_peak": ok.gamma[i],
                     "direction": ok.direction[i], "points": len(sub), "periodic_points": len(ok)})
    s = blade_system(BLADE_PRELOADS[0])
    th = np.radians(BLADE["theta_deg"])
    t = np.array([np.cos(th), 0.0, 0.0])
    bare = _linear_peak(s, s.K)  # no damper: neither its spring nor its friction
    stuck = _linear_peak(s, s.K_reference + BLADE["kt"] * np.outer(t, t))  # spring closed, contact stuck
    limits = pd.DataFrame({"limit": ["no damper", "damper stuck"], "peak_m": [bare[0], stuck[0]],
                           "gamma_peak": [bare[1], stuck[1]]})
    return {"curves": curves, "design": pd.DataFrame(rows), "limits": limits}


@register_figure("blade_damper", "A blade with a wedge damper whose normal load follows the blade's motion: "
                 "response curves for several preloads and peak response against preload", 91)
def blade_damper():
    return blade_data()


@blade_damper.plotter
def _plot_blade_damper(tables, out_dir):
    plt = pyplot()
    curves, design, limits = tables["curves"], tables["design"], tables["limits"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.6), layout="constrained")
    cmap = plt.get_cmap("viridis")
    shown = [p for p in BLADE_CURVES if p in set(curves.preload_N)]
    for j, p in enumerate(shown):
        color = cmap(j / max(len(shown) - 1, 1))
        for direction, ls, lw in (("up", "-", 1.5), ("down", "--", 1.0)):
            sub = curves[(curves.preload_N == p) & (curves.direction == direction)]
            ok = sub.status == "periodic"
            ax1.plot(sub.gamma, 1e3 * sub.amplitude_m.where(ok), ls, color=color, lw=lw,
                     label=f"P = {p:g} N" if direction == "up" else None)
            bad = sub[~ok]
            if len(bad):
                ax1.plot(bad.gamma, np.zeros(len(bad)), "x", color=color, ms=4)
    ax1.set_xlabel("gamma = w / w0")
    ax1.set_ylabel("tip amplitude, mm")
    ax1.set_title("Tip response, sweeps up (solid) and down (dashed); x at the axis: not periodic", fontsize=9)
    ax1.grid(alpha=0.3)
    ax2.plot(design.preload_N, 1e3 * design.peak_m, "o-", color="C0",
             label="peak tip amplitude, either sweep (time domain)")
    for (_, row), ls in zip(limits.iterrows(), (":", "--")):
        ax2.axhline(1e3 * row.peak_m, color="0.4", ls=ls, lw=1.0,
                    label=f"linear, {row.limit} (gamma = {row.gamma_peak:.3f})")
    best = design.loc[design.peak_m.idxmin()]
    ax2.plot([best.preload_N], [1e3 * best.peak_m], "*", color="C3", ms=12,
             label=f"optimum of the grid: P = {best.preload_N:g} N")
    ax2.set_xscale("log")
    ax2.set_xlabel("damper preload P, N")
    ax2.set_ylabel("peak tip amplitude, mm")
    ax2.set_title("Design chart", fontsize=9)
    # one legend below both panels: inside, it covered the limits' lines and curves
    h1, l1 = ax1.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    fig.legend(h1 + h2, l1 + l2, loc="outside lower center", ncol=5, fontsize=7, frameon=False)
    ax2.grid(alpha=0.3, which="both")
    fig.suptitle("Blade with a wedge damper whose normal load follows the platform's motion "
                 f"(theta = {BLADE['theta_deg']:g} deg, kn = {BLADE['kn']:g} N/m, tip force "
                 f"{BLADE['force_N']:g} N)", fontsize=10)
    return save_figure(fig, out_dir, "blade_damper")
