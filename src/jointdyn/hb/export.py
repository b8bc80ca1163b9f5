"""A harmonic-balance branch as an :class:`xarray.Dataset` (:func:`branch_dataset`), and the
attributes of its discretisation (:func:`discretisation_attrs`).

xarray is imported only here, when a Dataset is asked for.
"""

from __future__ import annotations

import math

import numpy as np

from .problem import amplitude_q_meaning, reference_scales
from .results import HBBranch, PointStatus
from .stability_schedule import ASSUMPTION

__all__ = ["branch_dataset", "discretisation_attrs", "pair_arrays"]


def branch_dataset(branch: HBBranch, response_dof: int | None = None):
    """xarray Dataset of a branch (dims ``point``, ``harmonic``, ``peak``).

    Variables per point: ``gamma``, the parameter (if not gamma),
    ``amplitude_q`` (kt X / fy of the first contact, X = half
    peak-to-peak of x(t) of ``response_dof``), ``amplitude_m`` (X, m),
    ``offset_m`` (mean, m), ``max_abs_m`` (m), ``stable``, ``fold``
    (turning points: the parameter is extremal along the computed branch,
    beyond a dead band of ``HBOptions.turning_band`` of the range, so that
    the corners of a piecewise-smooth branch, where it keeps its
    direction, are not folds), ``point_status`` (:class:`PointStatus`:
    how the point joins the one before it; a line is drawn only to
    ``joined`` and ``corner`` points), ``branch`` (segment index), ``gap``
    (reached by a jump), ``growth`` (max Re(s)/w of the Floquet
    exponents), ``aft_passes`` (periods marched), ``force_period`` (1; 2
    when the law alternated between two cycles and their mean was used; 0
    if the force did not repeat), ``harmonic_amplitude_m`` (dims point,
    harmonic: sqrt(a_k^2 + b_k^2), |a_0| for k = 0). Per peak (dim
    ``peak``): ``peak_gamma``, ``peak_<parameter>`` (if not gamma),
    ``peak_amplitude_q``, ``peak_amplitude_m``, ``peak_branch``,
    ``peak_refined``, ``peak_at_stop`` (:attr:`HBPeak.at_stop`),
    ``stability_checked`` (whether the point's label ``stable`` was
    computed; False: carried over from the checked points on both sides,
    growth NaN, ``StabilityOptions.check_every``).

    Attributes: ``status`` (:class:`~jointdyn.continuation.ContinuationStatus`;
    ``complete`` only when the range is covered), ``message`` (where and
    why segments stopped), ``uncovered`` (parts of the range without
    points, e.g. ``"1.164-1.185"``; empty when none), ``peaks``,
    ``peak_gamma`` and ``peak_amplitude_q`` (the highest peak, NaN
    without one), ``folds``, ``unstable_points``, ``stability_check_every``,
    ``stability_checked_points``, ``stability_assumption`` (what a label
    carried over assumes; empty when every point was checked) and the
    counters.
    """
    import xarray as xr

    p = branch.problem
    dof = branch.response_dof if response_dof is None else response_dof
    if not 0 <= dof < p.system.ndof:
        raise ValueError(f"response_dof must be in [0, {p.system.ndof - 1}], got {dof!r}")
    kt, fy = reference_scales(p.system)
    amp, off, mx = branch.response(dof)
    Xd = p.dof_coefficients(branch.X, dof, branch.lam) if branch.X.size else np.empty((0, p.nh))
    harm = np.empty((Xd.shape[0], p.H + 1))
    harm[:, 0] = np.abs(Xd[:, 0])
    for k in range(1, p.H + 1):
        harm[:, k] = np.hypot(Xd[:, 2 * k - 1], Xd[:, 2 * k])
    qs = kt / fy if fy > 0 else np.nan
    data = {
        "gamma": ("point", branch.gamma()),
        "amplitude_q": ("point", qs * amp),
        "amplitude_m": ("point", amp),
        "offset_m": ("point", off),
        "max_abs_m": ("point", mx),
        "stable": ("point", branch.stable),
        "fold": ("point", branch.fold),
        "point_status": ("point", np.array([str(s) for s in branch.point_status], dtype=str)),
        "branch": ("point", branch.segment),
        "gap": ("point", branch.gap),
        "growth": ("point", branch.growth),
        "stability_checked": ("point", branch.stability_checked),
        "aft_passes": ("point", branch.passes),
        "force_period": ("point", branch.force_period),
        "harmonic_amplitude_m": (("point", "harmonic"), harm),
        **_peak_variables(branch, dof, qs),
    }
    if branch.parameter != "gamma":
        data[branch.parameter] = ("point", branch.lam)
    data.update(_pair_variables(branch))
    attrs = {"gamma": {"long_name": "w / w0"},
             "amplitude_q": {"long_name": amplitude_q_meaning(p.system), "units": "1"},
             **{v: {"units": "m"} for v in ("amplitude_m", "offset_m", "max_abs_m", "harmonic_amplitude_m",
                                            "peak_amplitude_m")},
             "stability_checked": {"long_name": "the label stable was computed here (else carried over from the "
                                                "checked points on both sides)"},
             "point_status": {"flag_meanings": " ".join(s.value for s in PointStatus)},
             "pair_energy_J": {"units": "J", "long_name": "energy dissipated per cycle by each interface pair"},
             "energy_interface_J": {"units": "J", "long_name": "energy dissipated per cycle by all interface pairs"},
             "energy_pairs_J": {"units": "J", "long_name": "energy dissipated per cycle by all interface pairs",
                                "deprecated": "use energy_interface_J"},
             **{f"pair_{s}_fraction": {"units": "1", "long_name": f"fraction of the period the pair is {w}"}
                for s, w in (("stick", "stuck"), ("slip", "slipping"), ("open", "open"))}}
    # variables built with their attributes (no DataArray round trips afterwards)
    data = {k: xr.Variable(dims, np.asarray(v), attrs=attrs.get(k)) for k, (dims, v) in data.items()}
    coords = {"point": np.arange(branch.lam.size), "harmonic": np.arange(p.H + 1),
              "peak": np.arange(len(branch.peaks))}
    if p.has_interfaces:
        coords["pair"] = np.arange(p.pair_params.shape[0])
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(_branch_attrs(branch, dof, ds))
    return ds


def pair_arrays(branch: HBBranch) -> dict:
    """Per point and node pair of the interfaces (all interfaces stacked; empty without interfaces), the data
    of a slip map, arrays (points, pairs): ``pair_energy_J`` (energy dissipated per cycle, J),
    ``pair_stick_fraction``, ``pair_slip_fraction`` and ``pair_open_fraction`` (of the period, over the AFT
    samples), from one evaluation per point (:meth:`~jointdyn.hb.problem.HBProblem.pair_results`)."""
    p = branch.problem
    if not p.has_interfaces:
        return {}
    keys = (("energy_J", "pair_energy_J"), ("stick", "pair_stick_fraction"), ("slip", "pair_slip_fraction"),
            ("open", "pair_open_fraction"))
    out = {name: np.empty((branch.lam.size, p.pair_params.shape[0])) for _, name in keys}
    for i, (X, lam) in enumerate(zip(branch.X, branch.lam)):
        res = p.pair_results(X, p.evaluate(X, lam))
        for k, name in keys:
            out[name][i] = res[k]
    return out


def _pair_variables(branch: HBBranch) -> dict:
    """:func:`pair_arrays` as Dataset variables (dims point, pair), with ``energy_interface_J`` (dim point:
    the energy all pairs dissipate per cycle, J, which the point table carries; ``energy_pairs_J`` is its
    deprecated duplicate, kept for one release)."""
    out = {name: (("point", "pair"), v) for name, v in pair_arrays(branch).items()}
    if out:
        out["energy_interface_J"] = ("point", out["pair_energy_J"][1].sum(axis=1))
        out["energy_pairs_J"] = out["energy_interface_J"]
    return out


def _peak_variables(branch: HBBranch, dof: int, qs: float) -> dict:
    """Dataset variables on dim ``peak`` (see :func:`branch_dataset`)."""
    pk = branch.peaks
    p = branch.problem
    amp = [k.amplitude_m if dof == branch.response_dof else p.amplitudes(k.X, dof)[0] for k in pk]
    out = {
        "peak_gamma": ("peak", np.array([k.gamma for k in pk], dtype=float)),
        "peak_amplitude_q": ("peak", qs * np.array(amp, dtype=float)),
        "peak_amplitude_m": ("peak", np.array(amp, dtype=float)),
        "peak_branch": ("peak", np.array([k.segment for k in pk], dtype=int)),
        "peak_refined": ("peak", np.array([k.refined for k in pk], dtype=bool)),
        "peak_at_stop": ("peak", np.array([k.at_stop for k in pk], dtype=bool)),
    }
    if branch.parameter != "gamma":
        out["peak_" + branch.parameter] = ("peak", np.array([k.lam for k in pk], dtype=float))
    return out


def _branch_attrs(branch: HBBranch, dof: int, ds) -> dict:
    """Dataset attributes of a branch (see :func:`branch_dataset`)."""
    p = branch.problem
    top = int(np.argmax(ds.peak_amplitude_q.values)) if len(branch.peaks) else None
    return dict(
        status=branch.status.value,
        message=branch.message,
        uncovered=", ".join(f"{a:.6g}-{b:.6g}" for a, b in branch.uncovered),
        method="hb",
        parameter=branch.parameter,
        harmonics=p.H,
        samples=p.Ns,
        response_dof=dof,
        points=int(branch.lam.size),
        peaks=len(branch.peaks),
        peak_gamma=float(ds.peak_gamma.values[top]) if top is not None else math.nan,
        peak_amplitude_q=float(ds.peak_amplitude_q.values[top]) if top is not None else math.nan,
        folds=int(branch.fold.sum()),
        unstable_points=int((~branch.stable).sum()),
        stability=branch.stability if _computed(branch) else "not-computed",
        stability_check_every=int(branch.stability_check_every),
        stability_checked_points=int(branch.stability_checked.sum()),
        stability_assumption=ASSUMPTION if _computed(branch) and not branch.stability_checked.all() else "",
        condensed=int(p.condensed),
        unknown_dofs=int(p.n),
        max_aft_passes=int(branch.passes.max()) if branch.passes.size else 0,
        force_period_2_points=int((branch.force_period == 2).sum()),
        force_not_periodic_points=int((branch.force_period == 0).sum()),
        **{f"counter_{k}": int(v) for k, v in branch.counters.items()},
        **discretisation_attrs(branch),
    )


def _computed(branch: HBBranch) -> bool:
    """Whether the branch has its stability: a finite growth at every checked point, and a checked point
    where it has points."""
    checked = branch.stability_checked
    return bool(np.all(np.isfinite(branch.growth[checked])) and (checked.any() or checked.size == 0))


def discretisation_attrs(branch: HBBranch) -> dict:
    """Attributes of the choice of harmonics and samples and of its check (see :class:`DiscretisationCheck`).

    ``harmonics_choice`` and ``samples_choice`` (``auto`` or ``fixed``),
    ``discretisation_levels`` (the (H, Ns) of every branch computed, e.g.
    ``"7x128, 7x256"``), ``check_harmonics`` and ``check_samples`` (of the
    check solves, 0 where none was made), ``check_harmonics_change`` and
    ``check_samples_change`` (largest relative change of a peak amplitude;
    NaN without a check), ``check_rtol``, ``check_converged`` (1/0) and
    ``check_peaks``.
    """
    d = branch.discretisation
    if d is None:
        p = branch.problem
        return dict(harmonics_choice="fixed", samples_choice="fixed", discretisation_levels=f"{p.H}x{p.Ns}")
    return dict(
        harmonics_choice="auto" if d.harmonics_auto else "fixed",
        samples_choice="auto" if d.samples_auto else "fixed",
        discretisation_levels=", ".join(f"{h}x{n}" for h, n in d.levels),
        check_harmonics=d.check_harmonics,
        check_samples=d.check_samples,
        check_harmonics_change=float(d.harmonics_change),
        check_samples_change=float(d.samples_change),
        check_rtol=float(d.rtol),
        check_converged=int(d.converged),
        check_peaks=d.peaks,
    )
