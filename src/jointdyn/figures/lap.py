"""The bolted lap joint's figure.

``lap_joint``
    The lap joint shipped with jointdyn (:func:`jointdyn.fe.lap_joint`: two
    steel plates, one bolt, a patch of 264 node pairs of which the 120 that
    carry the bolt's load at rest are the model's interface, 733 reduced
    DOFs) with that interface (:class:`jointdyn.interfaces.Interface`; the
    static contact solve that made the model found the other 144 apart, and
    the element has no initial gap: given to it, they would touch at zero
    load and clap in every cycle, so the model keeps their nodes as interior
    DOFs), and the plates' modal damping
    (:data:`LAP_ZETA`): (a) the first
    bending mode's natural frequency and (b) its damping ratio against the
    first-harmonic amplitude of the output DOF (EPMC backbone,
    :func:`jointdyn.modes.epmc`); (c) the forced response near it to a force
    at the output DOF, synthesised from that nonlinear mode
    (:func:`jointdyn.modes.single_mode_frc`: at the 733 DOFs of the model a
    harmonic-balance branch with its Hill stability is beyond what this
    figure can afford today, docs/lap-joint.md);
    (d) and (e) maps of the patch at three amplitudes of the backbone: per
    pair the fraction of the period it slips (d) and the fraction it is open
    (e), with the energy the pairs dissipate per cycle above each column.
    Settings: the ``LAP_*`` constants of this module.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._registry import pyplot, register_figure, save_figure

__all__ = ["lap_joint_system", "lap_joint_data"]

#: harmonics and AFT samples per period of its backbone. The reduced model has
#: 733 DOFs, so an HB or EPMC Newton step solves 733 (2H + 1) unknowns with a dense LU: with
#: H = 1 a backbone point costs about 1 s here. Against H = 3 (64 samples), H = 1 gives the first
#: bending frequency within 0.1 % and its damping ratio within 2 % at the onset of slip (3e-5 m)
#: and to three digits at the largest damping (3e-4 m) (docs/lap-joint.md)
LAP_HARMONICS = 1
LAP_SAMPLES = 32
#: backbone range: first-harmonic amplitude of the output DOF, m (stuck below 4.5e-6 m)
LAP_AMPLITUDE_M = (1e-6, 2e-3)
#: largest arc-length step of the backbone (47 points over the range, most of them between 4.5e-6
#: and 3e-4 m, where the pairs start to slip one after another)
LAP_DS_MAX = 0.04
#: amplitudes of the three slip maps, m: the onset of slip, the largest damping, deep slip
LAP_SLIP_MAP_M = (3e-5, 3e-4, 1.5e-3)
#: modal damping ratio of every mode of the plates (material damping)
LAP_ZETA = 1e-3
#: forced response (synthesised from the backbone): force amplitude at the output DOF, N
LAP_FORCE_N = 30.0


def lap_joint_system(force_n: float = LAP_FORCE_N, zeta: float = LAP_ZETA):
    """``(system, lap_joint)``: the shipped lap joint (:func:`jointdyn.fe.lap_joint`) as a
    :class:`~jointdyn.systems.System`: its reduced M and K, modal damping ``zeta`` of every mode of the
    structure with its pairs stuck, one interface of its pairs (those loaded at rest: their kt, kn, mu and
    preload) and a force of amplitude ``force_n`` (N) at the output DOF, which is also the system's
    output."""
    from ..fe import lap_joint
    from ..interfaces import Interface
    from ..systems import System, modal_damping

    lj = lap_joint()
    itf = Interface(kt=lj.kt, kn=lj.kn, mu=lj.mu, preload=lj.preload, pairs=lj.pairs)
    force = np.zeros(lj.M.shape[0])
    force[lj.output_dof] = force_n
    C = modal_damping(lj.M, lj.linear_K("stuck"), zeta)
    return System(M=lj.M, C=C, K=lj.K, interfaces=(itf,), force=force, output_dof=lj.output_dof), lj


def _backbone_table(bb) -> pd.DataFrame:
    return pd.DataFrame({"amplitude_m": bb.amplitude_m, "frequency_hz": bb.omega_rad_s / (2.0 * math.pi),
                         "damping_ratio": bb.damping_ratio, "damping_ratio_contacts": bb.damping_ratio_contacts,
                         "damping_ratio_viscous": bb.damping_ratio_viscous,
                         "status": str(bb.status.value), "harmonics": bb.harmonics, "samples": bb.samples})


def _slip_table(bb, amplitudes, lj) -> pd.DataFrame:
    """Per pair of the patch, at each amplitude: the backbone solved at exactly that amplitude (Newton from
    its nearest point), and the fractions of the period each pair is stuck, slipping and open and its energy
    per cycle; after the model's pairs, the patch's pairs apart at rest, which are not in the model
    (``in_interface`` False, ``pair`` -1, NaN results)."""
    problem = bb.problem
    nopen = lj.open_xy.shape[0]
    on = np.concatenate([np.ones(lj.npairs, bool), np.zeros(nopen, bool)])
    xy = np.concatenate([lj.xy, lj.open_xy])
    rows = []
    for k, a in enumerate(amplitudes):
        i = int(np.argmin(np.abs(np.log(bb.amplitude_m / a))))
        guess = bb.X[i] / bb.amplitude_m[i]  # the scaled unknowns of point i (EPMCProblem.unpack reversed)
        guess[problem.i_omega] = bb.omega_rad_s[i] / problem.w_ref
        guess[problem.i_xi] = bb.xi_rad_s[i] / problem.w_ref
        v, ok, _ = problem.solve(a, guess)
        X, w, xi = problem.unpack(v, math.log10(a))
        res = problem.hb.pair_results(X, problem.evaluate(X, w))
        full = {key: np.concatenate([values, np.full(nopen, np.nan)]) for key, values in res.items()}
        rows.append(pd.DataFrame({"map": k, "amplitude_m": a, "converged": bool(ok), "frequency_hz": w / (2 * math.pi),
                                  "damping_ratio": xi / (2.0 * w), "in_interface": on,
                                  "pair": np.concatenate([np.arange(lj.npairs), np.full(nopen, -1)]),
                                  "x_mm": 1e3 * xy[:, 0], "y_mm": 1e3 * xy[:, 1],
                                  "preload_N": np.concatenate([lj.preload, np.zeros(nopen)]),
                                  "stick": full["stick"], "slip": full["slip"], "open": full["open"],
                                  "energy_J": full["energy_J"]}))
    return pd.concat(rows, ignore_index=True)


def _frc_table(bb, system) -> pd.DataFrame:
    """The forced response of ``system`` (its force) synthesised from the backbone ``bb``."""
    from ..modes import single_mode_frc

    ds = single_mode_frc(bb, system)
    return pd.DataFrame({"frequency_hz": ds.omega_rad_s.values / (2.0 * math.pi), "amplitude_m": ds.amplitude_m.values,
                         "flank": ds.flank.values, "status": ds.attrs["status"],
                         "force_N": float(system.force[system.output_dof])})


def lap_joint_data(harmonics=LAP_HARMONICS, samples=LAP_SAMPLES, amplitude=LAP_AMPLITUDE_M,
                   maps=LAP_SLIP_MAP_M, force_n=LAP_FORCE_N):
    """The backbone, the forced response and the slip maps of the lap joint as three tables."""
    from ..modes import epmc

    system, lj = lap_joint_system(force_n)
    bb = epmc(system, amplitude, harmonics=harmonics, samples=samples, ds_max=LAP_DS_MAX, progress=False)
    return {"backbone": _backbone_table(bb), "frc": _frc_table(bb, system), "slip": _slip_table(bb, maps, lj)}


@register_figure("lap_joint", "The bolted lap joint (its 120 loaded node pairs, 733 DOFs): first bending mode's "
                 "frequency and damping against amplitude (EPMC), forced response near it (HB), slip maps", 90)
def lap_joint_figure():
    return lap_joint_data()


def _plot_frc(ax, frc, bb):
    """The synthesised forced response (both flanks through the peak) over the backbone."""
    ax.plot(frc.frequency_hz, 1e3 * frc.amplitude_m, "-", color="C0", lw=1.4,
            label=f"forced response, {frc.force_N.iloc[0]:g} N at the output DOF")
    ax.plot(bb.frequency_hz, 1e3 * bb.amplitude_m, ":", color="0.4", lw=1.0, label="backbone")
    ax.set_yscale("log")
    lo, hi = bb.frequency_hz.min(), bb.frequency_hz.max()  # the resonance: the backbone's range and a margin
    ax.set_xlim(lo - 0.5 * (hi - lo), hi + 0.5 * (hi - lo))
    ax.set_title(f"(c) forced response from the mode: {frc.status.iloc[0]}", fontsize=9)
    ax.set_xlabel("forcing frequency (Hz)")
    ax.set_ylabel("first-harmonic amplitude of the output DOF (mm)")
    ax.legend(fontsize=7, loc="upper left")


def _plot_maps(axes, slip):
    """Two rows of patch maps: fraction of the period slipping, fraction open."""
    for col, (k, sub) in enumerate(slip.groupby("map")):
        for row, (key, cmap, label) in enumerate((("slip", "viridis", "fraction of the period slipping"),
                                                  ("open", "magma", "fraction of the period open"))):
            ax = axes[row, col]
            on = sub.in_interface.to_numpy().astype(bool)
            ax.scatter(sub.x_mm[~on], sub.y_mm[~on], s=36, marker="s", facecolors="none", edgecolors="0.7",
                       linewidths=0.5)
            sc = ax.scatter(sub.x_mm[on], sub.y_mm[on], c=sub[key][on], cmap=cmap, vmin=0.0, vmax=1.0, s=36,
                            marker="s", edgecolors="k", linewidths=0.4)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if row == 0:
                a = sub.amplitude_m.iloc[0]
                note = "" if bool(sub.converged.iloc[0]) else " (Newton did not converge)"
                ax.set_title(f"a = {1e3 * a:.3g} mm, {sub.frequency_hz.iloc[0]:.1f} Hz{note}\n"
                             f"pairs dissipate {1e3 * sub.energy_J.sum():.3g} mJ per cycle", fontsize=8)
            if col == 0:
                ax.set_ylabel(f"({'de'[row]}) " + label, fontsize=8)  # one letter per row of maps
        last = sc
    return last


@lap_joint_figure.plotter
def _plot_lap_joint(tables, out_dir):
    plt = pyplot()
    bb, frc, slip = tables["backbone"], tables["frc"], tables["slip"]
    fig = plt.figure(figsize=(12, 10), layout="constrained")
    top, bottom = fig.subfigures(2, 1, height_ratios=[1.0, 1.25])
    ax1, ax2, ax3 = top.subplots(1, 3)
    ax1.semilogx(bb.amplitude_m * 1e3, bb.frequency_hz, "-", color="C0", lw=1.5)
    ax1.set_ylabel("natural frequency (Hz)")
    ax1.set_title(f"(a) first bending mode, EPMC: {bb.status.iloc[0]}", fontsize=9)
    ax2.semilogx(bb.amplitude_m * 1e3, bb.damping_ratio, "-", color="C0", lw=1.5, label="total")
    ax2.semilogx(bb.amplitude_m * 1e3, bb.damping_ratio_contacts, "--", color="C3", lw=1.2, label="the joint's pairs")
    ax2.semilogx(bb.amplitude_m * 1e3, bb.damping_ratio_viscous, ":", color="0.4", lw=1.2,
                 label="the plates (viscous)")
    ax2.set_ylabel("damping ratio")
    ax2.set_title("(b) its damping ratio", fontsize=9)
    ax2.legend(fontsize=7)
    for ax in (ax1, ax2):
        ax.set_xlabel("first-harmonic amplitude of the output DOF (mm)")
        ax.grid(alpha=0.3, which="both")
        for a in slip.amplitude_m.unique():
            ax.axvline(a * 1e3, color="0.6", lw=0.7, ls=":")
    _plot_frc(ax3, frc, bb)
    ax3.grid(alpha=0.3)
    axes = bottom.subplots(2, slip["map"].nunique(), squeeze=False)
    last = _plot_maps(axes, slip)
    bottom.colorbar(last, ax=axes, shrink=0.8, label="fraction of the period")
    n_on = int(slip[slip["map"] == 0].in_interface.sum())
    fig.suptitle(f"Bolted lap joint, 733 DOFs: the {n_on} node pairs loaded at rest (H = {int(bb.harmonics.iloc[0])}, "
                 f"{int(bb.samples.iloc[0])} samples per period); slip maps: open squares = pairs apart at rest",
                 fontsize=10)
    return save_figure(fig, out_dir, "lap_joint")
