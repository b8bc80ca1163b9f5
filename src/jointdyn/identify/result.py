"""The result of a fit: parameters with standard errors, or the reason they are unknown."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..status import Status

__all__ = ["FitStatus", "FitResult", "covariance"]


class FitStatus(Status):
    """Outcome of a fit (:func:`jointdyn.fit_loops`, :func:`jointdyn.fit_backbone`)."""

    IDENTIFIED = "identified", "least squares converged and every parameter is determined by the data", True
    PARTLY_IDENTIFIED = ("partly-identified", "least squares converged but the data do not determine some "
                         "parameters (see not_identifiable)")
    NOT_CONVERGED = "not-converged", "least squares stopped at its evaluation limit before converging"
    REFINE_FAILED = ("refine-failed", "an EPMC backbone of the refinement did not cover the amplitudes: the "
                     "parameters are those of the describing function")


@dataclass(frozen=True)
class FitResult:
    """A fitted joint model.

    Attributes
    ----------
    kind : {"loops", "backbone"}
        What was fitted.
    model : str
        Contact-law name.
    status : FitStatus
        Outcome (``status.ok``: every parameter determined).
    message : str
        One line on the outcome (the reasons of parameters not identifiable).
    parameters : dict
        Fitted values by name: ``kt`` (N/m), ``mu`` (-), ``fy_N`` (N, = mu n_ref for
        loops), ``chi``, ``beta`` (-; Segalman), and for backbones ``k`` (N/m) and
        ``zeta`` (-). ``None`` where the data do not determine the parameter.
    standard_errors : dict
        Standard errors by the same names (None where not identifiable), from the
        Jacobian at the optimum and the residual variance.
    names : tuple of str
        The fitted (free) parameters, in the order of ``correlation``.
    correlation : ndarray (p, p)
        Correlation matrix of the identified parameters among ``names`` (NaN rows for
        parameters not identifiable).
    not_identifiable : dict
        Parameter name -> reason, for the parameters the data do not determine.
    rms_residual : float
        Root mean square of the residuals: N for loops (force), and for backbones of the
        relative frequency and damping residuals (-).
    n_ref : float or None
        Reference normal load of a loop fit, N (mu = fy_N / n_ref).
    law : ContactLaw or None
        The fitted law (with the start values in place of parameters not identifiable).
    measured, fitted : dict
        The data and the fitted model's values (arrays by column name).
    evaluations : int
        Model evaluations of the least squares.
    intervals : dict
        Name -> :class:`jointdyn.identify.Interval`: the profile-likelihood interval at
        ``jointdyn.identify._profile.FIT_LEVEL`` (95 %) of every fitted parameter, all the others refitted at each point (so not
        conditional on any held value). ``low`` or ``high`` None: the data do not bound
        the parameter on that side (it is then in ``not_identifiable``).
    conditional_on : tuple of str
        The parameters held at their fitted values when ``standard_errors`` were computed
        (the linearised errors of the others are conditional on them; the intervals are
        not).
    determined_combinations : dict
        Name -> {"value", "interval", "unit", "meaning"}: combinations of the parameters
        the data determine when some parameters are not determined separately (a backbone
        in microslip: ``k_plus_kt``, ``R``, ``chi``, ``zeta``).
    record_start : str or None
        Loops: how the initial slip state was set (from rest, or by the record's first
        stroke, whose samples are then not fitted).
    damping_range : dict or None
        Ring-downs (:func:`jointdyn.identify.fit_ringdown`): the amplitudes over which the fitted
        model's damping ratio is determined within ``bound`` (relative half-width of its 95 %
        interval, from the windows' measured noise): ``amplitude_high_m``, ``amplitude_low_m``
        (None: nowhere), ``points``, ``trimmed_top``, ``trimmed_bottom`` (backbone points outside),
        ``bound``, ``level``, ``half_width`` and ``determined`` (per point), ``meaning``. None:
        not a ring-down fit, or one whose range was not assessed.
    """

    kind: str
    model: str
    status: FitStatus
    message: str
    parameters: dict
    standard_errors: dict
    names: tuple
    correlation: np.ndarray
    not_identifiable: dict
    rms_residual: float
    n_ref: float | None = None
    law: object = None
    measured: dict = field(default_factory=dict)
    fitted: dict = field(default_factory=dict)
    evaluations: int = 0
    intervals: dict = field(default_factory=dict)
    conditional_on: tuple = ()
    determined_combinations: dict = field(default_factory=dict)
    record_start: str | None = None
    damping_range: dict | None = None

    def to_dict(self) -> dict:
        """The result as JSON-ready values (keys ``parameters``, ``standard_errors``,
        ``rms_residual``, ``status`` and more; ``intervals``: name -> {low, high, level,
        method} or None; ``standard_errors_conditional_on``; ``determined_combinations``)."""
        corr = [[None if not np.isfinite(v) else float(v) for v in row] for row in self.correlation]
        return {
            "kind": self.kind,
            "model": self.model,
            "status": self.status.value,
            "message": self.message,
            "parameters": dict(self.parameters),
            "standard_errors": dict(self.standard_errors),
            "not_identifiable": dict(self.not_identifiable),
            "correlation": {"names": list(self.names), "matrix": corr},
            "rms_residual": float(self.rms_residual),
            "n_ref_N": self.n_ref,
            "evaluations": int(self.evaluations),
            "intervals": {k: (None if v is None else v.to_dict()) for k, v in self.intervals.items()},
            "standard_errors_conditional_on": list(self.conditional_on),
            "determined_combinations": {k: dict(v) for k, v in self.determined_combinations.items()},
            "record_start": self.record_start,
            "damping_range": None if self.damping_range is None else dict(self.damping_range),
        }


def covariance(jac: np.ndarray, residual: np.ndarray, keep: np.ndarray, xtol: float) -> np.ndarray:
    """Covariance of the parameters ``keep`` (boolean mask) from the Jacobian of the
    residuals at the optimum and the residual variance sum(r^2) / (m - p); the other
    parameters are held (their rows and columns are NaN). Parameters whose columns are
    linearly dependent (a singular value at most ``xtol`` x 1e-4 times the largest; the fits
    pass their least-squares tolerance ``_lsq.FIT_XTOL``) get an infinite variance."""
    p = jac.shape[1]
    cov = np.full((p, p), np.nan)
    idx = np.flatnonzero(keep)
    if idx.size == 0:
        return cov
    J = jac[:, idx]
    dof = max(jac.shape[0] - idx.size, 1)
    s2 = float(residual @ residual) / dof
    u, sv, vt = np.linalg.svd(J, full_matrices=False)
    tiny = sv <= sv[0] * xtol * 1e-4 if sv.size and sv[0] > 0.0 else np.ones(sv.size, bool)
    inv = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, sv) ** 2)
    c = (vt.T * inv) @ vt * s2
    if np.any(tiny):  # directions the data do not see: infinite variance along them
        null = np.abs(vt[tiny]).max(axis=0) > 1e-8
        c[null, :] = np.inf
        c[:, null] = np.inf
    cov[np.ix_(idx, idx)] = c
    return cov


def correlation(cov: np.ndarray) -> np.ndarray:
    """Correlation matrix of a covariance (NaN where a variance is not finite or zero)."""
    sd = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        out = cov / np.outer(sd, sd)
    out[~np.isfinite(out)] = np.nan
    return out
