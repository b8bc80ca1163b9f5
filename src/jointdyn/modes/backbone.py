"""Backbones of nonlinear modes: the result object, its status and its Dataset.

A backbone is a nonlinear mode followed in amplitude: per point the
first-harmonic amplitude of the output DOF (m), the natural frequency
(rad/s), the modal damping ratio and its parts, the harmonics of the mode
shape and the energy each contact dissipates per cycle. It is computed by
:func:`jointdyn.modes.epmc` (the extended periodic motion concept) or
:func:`jointdyn.modes.qsma` (quasi-static modal analysis) and turned into an
:class:`xarray.Dataset` by :func:`backbone_dataset`.

Damping-ratio convention (docs/modes.md): ``damping_ratio`` is
D = xi / (2 omega), the self-excitation xi of the EPMC (1/s) that cancels
*all* the dissipation over a period, by the contacts and by the viscous
damping C. By the energy balance of the mode it splits exactly into
``damping_ratio_contacts + damping_ratio_viscous``, each being the energy
dissipated per cycle over ``2 omega int(x'^T M x' dt)``. For a modal C
(:func:`jointdyn.modal_damping` with ratio zeta_r) the viscous part is
zeta_r at the linear limit and zeta_r omega_r / omega along the backbone
while the mode shape stays the linear one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..status import Status
from ..systems import System
from ._free import LinearMode

__all__ = ["ModeStatus", "Backbone", "backbone_dataset", "pair_fractions"]


class ModeStatus(Status):
    """How a nonlinear-mode computation ended (backbones and single-mode synthesis)."""

    COMPLETE = "complete", "the computation covers the requested amplitude range", True
    MAX_POINTS = "max-points", "the backbone stopped at the bound on its number of points"
    FAILED = "failed", "the solver failed: the backbone stops short of the amplitude range (its points are kept)"
    NO_START = "no-start", "no solution at the smallest amplitude: the backbone is empty"
    PEAK_ABOVE_RANGE = ("peak-above-range", "the resonance peak lies above the backbone's amplitude range (or the "
                        "forced response is unbounded): the curve stops at the largest amplitude")
    PEAK_BELOW_RANGE = "peak-below-range", "the resonance peak lies below the backbone's smallest amplitude"


@dataclass(frozen=True)
class Backbone:
    """A nonlinear mode followed in amplitude (built by :func:`~jointdyn.modes.epmc` or :func:`~jointdyn.modes.qsma`).

    Attributes
    ----------
    method : str
        ``"epmc"`` or ``"qsma"``.
    status : ModeStatus
        ``status.ok`` only for a complete backbone.
    message : str
        What happened, with the amplitude where it stopped.
    system : System
        The structure (its forcing is not used by the mode).
    linear : LinearMode
        The linear stuck mode the backbone starts from.
    output_dof : int
        DOF whose first-harmonic amplitude is the backbone's amplitude.
    harmonics, samples : int
        Harmonics 0..H and AFT samples per period (QSMA: 1 and 0).
    amplitude_m : ndarray (points,)
        First-harmonic amplitude of the output DOF, m (QSMA: its static
        displacement at the push's turning point).
    omega_rad_s : ndarray (points,)
        Natural frequency of the nonlinear mode, rad/s.
    xi_rad_s : ndarray (points,)
        Self-excitation coefficient xi = 2 D omega, 1/s.
    damping_ratio : ndarray (points,)
        D = xi / (2 omega) (module docstring).
    damping_ratio_contacts, damping_ratio_viscous : ndarray (points,)
        Its parts from the contacts and from C; they add up to D.
    modal_amplitude : ndarray (points,)
        q = sqrt(a1^T M a1 + b1^T M b1) of the first-harmonic coefficients
        a1, b1 (kg^1/2 m): the mass-weighted amplitude of the mode.
    X : ndarray (points, n (2H + 1))
        Harmonic coefficients of the mode shape, harmonic-major
        (``X[h * n + i]``: coefficient h of DOF i; the basis of
        :mod:`jointdyn.fourier`), m.
    contact_energy_J : ndarray (points, contacts)
        Energy dissipated per cycle by each contact, J.
    energy_viscous_J : ndarray (points,)
        Energy dissipated per cycle by C, J.
    counters : dict
        Solver counters (points, residual evaluations, rejected steps, ...).
    problem : object, optional
        The EPMC residual (:class:`~jointdyn.modes.EPMCProblem`) for EPMC
        backbones, used to solve further points on the same mode.
    reduction : CraigBampton, optional
        The Craig-Bampton reduction the backbone was computed on
        (``epmc(..., reduce=n_modes)``); then ``system``, ``linear``,
        ``output_dof``, ``X`` and ``problem`` are the reduced model's, the
        amplitudes, frequencies, damping ratios and energies those of the
        full model (the output DOF and the contact DOFs are kept as they
        are), and ``reduction.error`` compares the linear modes with the
        full model's. None: computed on the full model.
    """

    method: str
    status: ModeStatus
    message: str
    system: System
    linear: LinearMode
    output_dof: int
    harmonics: int
    samples: int
    amplitude_m: np.ndarray
    omega_rad_s: np.ndarray
    xi_rad_s: np.ndarray
    damping_ratio: np.ndarray
    damping_ratio_contacts: np.ndarray
    damping_ratio_viscous: np.ndarray
    modal_amplitude: np.ndarray
    X: np.ndarray
    contact_energy_J: np.ndarray
    energy_viscous_J: np.ndarray
    #: energy dissipated per cycle by each node pair of the interfaces (points, pairs), J (None without)
    pair_energy_J: np.ndarray | None = None
    counters: dict = field(default_factory=dict)
    problem: object = None
    reduction: object = None

    @property
    def points(self) -> int:
        """Number of points."""
        return int(self.amplitude_m.size)

    @property
    def full_output_dof(self) -> int:
        """The output DOF in the full model's numbering."""
        return self.output_dof if self.reduction is None else int(self.reduction.boundary[self.output_dof])

    def full_shape(self) -> np.ndarray:
        """Harmonic coefficients of the mode shape on the full model's DOFs, (points, N (2H + 1)), m.

        ``X`` itself without a reduction; otherwise each harmonic expanded
        by x = T q (harmonic-major, as ``X``).
        """
        if self.reduction is None:
            return self.X
        r = self.reduction.size
        q = self.X.reshape(-1, r)  # rows: (point, coefficient)
        return (q @ self.reduction.T.T).reshape(self.points, -1)


def _harmonic_amplitudes(X: np.ndarray, H: int, n: int) -> np.ndarray:
    """sqrt(a_k^2 + b_k^2) per point, harmonic and DOF (|a_0| for k = 0): (points, H + 1, n), m."""
    Xm = X.reshape(-1, 2 * H + 1, n)
    out = np.empty((Xm.shape[0], H + 1, n))
    out[:, 0] = np.abs(Xm[:, 0])
    for k in range(1, H + 1):
        out[:, k] = np.hypot(Xm[:, 2 * k - 1], Xm[:, 2 * k])
    return out


def pair_fractions(backbone: Backbone) -> dict:
    """Per point and interface node pair, the fractions of the period each pair is stuck, slipping and open
    (over the AFT samples; one evaluation per point of the backbone's problem): ``{"stick": (array
    (points, pairs), "stuck"), "slip": ..., "open": ...}``; empty without pairs or without the problem."""
    p = backbone.problem
    if backbone.pair_energy_J is None or p is None or not hasattr(p, "hb"):
        return {}
    out = {k: np.empty(backbone.pair_energy_J.shape) for k in ("stick", "slip", "open")}
    for i in range(backbone.points):
        X, w = backbone.X[i], backbone.omega_rad_s[i]
        res = p.hb.pair_results(X, p.evaluate(X, w))
        for k in out:
            out[k][i] = res[k]
    return {k: (v, w) for (k, v), w in zip(out.items(), ("stuck", "slipping", "open"))}


#: Dataset variables renamed to the energy rule (docs/architecture.md), new name -> old name: the old one
#: is written as a deprecated duplicate for one release (CHANGELOG)
DEPRECATED_VARIABLES = {"contact_energy_J": "energy_contact_J", "energy_interface_J": "energy_pairs_J"}


def _deprecated_duplicates(data: dict) -> None:
    """Add the deprecated duplicates of :data:`DEPRECATED_VARIABLES` to ``data`` (variables by name)."""
    for new, old in DEPRECATED_VARIABLES.items():
        if new in data:
            dims, values, attrs = data[new]
            data[old] = (dims, values, {**attrs, "deprecated": f"use {new}"})


def backbone_dataset(backbone: Backbone):
    """xarray Dataset of a backbone (dim ``point``).

    Variables: ``amplitude_m`` (first-harmonic amplitude of the output DOF),
    ``amplitude_q`` (kt a / fy of the first contact), ``omega_rad_s``,
    ``frequency_hz``, ``gamma`` (omega / w0, w0 of the System),
    ``omega_ratio`` (omega over the linear stuck frequency),
    ``damping_ratio``, ``damping_ratio_contacts``,
    ``damping_ratio_viscous``, ``xi_rad_s``, ``modal_amplitude``,
    ``energy_viscous_J``; ``contact_energy_J`` (point, contact; ``energy_contact_J``
    is a deprecated duplicate, kept for one release);
    ``mode_shape_m`` (point, coefficient, dof): the harmonic coefficients
    (0, cos 1, sin 1, ..., cos H, sin H); ``harmonic_amplitude_m`` (point,
    harmonic, dof); with interfaces (dim ``pair``: their node pairs one after the other) ``pair_energy_J``
    (energy per cycle of each pair, J), ``energy_interface_J`` (dim point: their sum, J;
    ``energy_pairs_J`` is a deprecated duplicate) and
    ``pair_stick_fraction``, ``pair_slip_fraction``, ``pair_open_fraction`` (of the period; the data of a
    slip map, :func:`pair_fractions`). Attributes: ``method``, ``status``, ``message``,
    ``linear_mode`` (the linear stuck mode it starts from; the name
    ``mode`` is taken by netCDF files), ``output_dof``, ``harmonics``, ``samples``,
    ``omega_linear_rad_s``, ``w0_rad_s``, ``model`` and ``law`` (class
    name and parameters of the first contact's law), ``points`` and the solver counters (``counter_*``).
    A backbone on a reduction (``epmc(..., reduce=n)``) has ``dof`` over the
    reduced coordinates and the attributes ``full_output_dof``,
    ``reduction_modes`` and ``reduction_boundary_dofs`` (full-model DOFs).
    """
    import xarray as xr

    b = backbone
    s = b.system
    n, H = s.ndof, b.harmonics
    from ..hb.problem import amplitude_q_meaning, reference_scales

    kt, fy = reference_scales(s)
    scale = fy / kt
    law = s.contacts[0].law if s.contacts else None
    X = b.X.reshape(-1, 2 * H + 1, n) if b.X.size else np.empty((0, 2 * H + 1, n))
    point = ("point",)
    data = {
        "amplitude_m": (point, b.amplitude_m, {"units": "m", "long_name": "first-harmonic amplitude of the output DOF"}),
        "amplitude_q": (point, b.amplitude_m / scale if scale > 0 else b.amplitude_m * np.nan,
                        {"units": "1", "long_name": amplitude_q_meaning(s).replace(" X ", " a ")}),
        "omega_rad_s": (point, b.omega_rad_s, {"units": "rad/s", "long_name": "natural frequency"}),
        "frequency_hz": (point, b.omega_rad_s / (2.0 * np.pi), {"units": "Hz"}),
        "gamma": (point, b.omega_rad_s / s.w0, {"long_name": "omega / w0"}),
        "omega_ratio": (point, b.omega_rad_s / b.linear.omega_rad_s, {"long_name": "omega / linear stuck frequency"}),
        "damping_ratio": (point, b.damping_ratio, {"units": "1", "long_name": "modal damping ratio xi / (2 omega)"}),
        "damping_ratio_contacts": (point, b.damping_ratio_contacts, {"units": "1"}),
        "damping_ratio_viscous": (point, b.damping_ratio_viscous, {"units": "1"}),
        "xi_rad_s": (point, b.xi_rad_s, {"units": "1/s", "long_name": "self-excitation coefficient"}),
        "modal_amplitude": (point, b.modal_amplitude, {"units": "kg^0.5 m"}),
        "energy_viscous_J": (point, b.energy_viscous_J, {"units": "J", "long_name": "energy dissipated per cycle by C"}),
        "contact_energy_J": (("point", "contact"), b.contact_energy_J,
                             {"units": "J", "long_name": "energy dissipated per cycle by each contact"}),
        "mode_shape_m": (("point", "coefficient", "dof"), X, {"units": "m"}),
        "harmonic_amplitude_m": (("point", "harmonic", "dof"), _harmonic_amplitudes(b.X, H, n), {"units": "m"}),
    }
    if b.pair_energy_J is not None:
        data["pair_energy_J"] = (("point", "pair"), b.pair_energy_J,
                                 {"units": "J", "long_name": "energy dissipated per cycle by each interface pair"})
        data["energy_interface_J"] = (point, b.pair_energy_J.sum(axis=1),
                                      {"units": "J", "long_name": "energy dissipated per cycle by all interface pairs"})
        for key, (values, what) in pair_fractions(b).items():
            data[f"pair_{key}_fraction"] = (("point", "pair"), values,
                                            {"units": "1", "long_name": f"fraction of the period the pair is {what}"})
    _deprecated_duplicates(data)
    variables = {k: xr.Variable(dims, np.asarray(v), attrs=a) for k, (dims, v, a) in data.items()}
    coords = {"point": np.arange(b.points), "contact": np.arange(len(s.contacts)),
              "coefficient": np.arange(2 * H + 1), "harmonic": np.arange(H + 1), "dof": np.arange(n)}
    ds = xr.Dataset(variables, coords=coords)
    ds.attrs.update(method=b.method, status=b.status.value, message=b.message, linear_mode=b.linear.index,
                    output_dof=b.output_dof, harmonics=H, samples=b.samples,
                    omega_linear_rad_s=b.linear.omega_rad_s, w0_rad_s=s.w0,
                    model=law.name if law is not None else "interface", law=repr(law) if law is not None else "",
                    points=b.points,
                    **{f"counter_{k}": int(v) for k, v in b.counters.items()})
    if b.reduction is not None:  # dof: the reduced coordinates (boundary DOFs first)
        ds.attrs.update(full_output_dof=b.full_output_dof, reduction_modes=int(b.reduction.interior_w_rad_s.size),
                        reduction_boundary_dofs=np.asarray(b.reduction.boundary, dtype=np.int32))  # netCDF3: int32
    return ds
