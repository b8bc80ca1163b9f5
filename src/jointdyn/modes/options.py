"""What a nonlinear mode is asked apart from its system and its amplitudes: :class:`EPMCOptions` (the
extended periodic motion concept's own numbers) and :class:`QSMAOptions` (the quasi-static push's).

The harmonic-balance numbers of the EPMC's evaluation (the Jacobian's form, the bounds of the automatic
discretisation) are :class:`~jointdyn.hb.options.HBOptions`, passed to :func:`~jointdyn.modes.epmc` as
``hb_options``; its step control beyond the defaults below is
:class:`~jointdyn.continuation.ContinuationOptions`."""

from __future__ import annotations

from dataclasses import dataclass

from .. import _validate as V

__all__ = ["EPMCOptions", "QSMAOptions", "epmc_options", "qsma_options"]


@dataclass(frozen=True)
class EPMCOptions:
    """The EPMC's own numbers, with their defaults.

    The continuation runs in log10 of the amplitude (unknowns scaled by the amplitude, frequency and
    self-excitation by the linear frequency, residual by the stiffness times the amplitude).

    Attributes
    ----------
    ds_start : float
        First arc-length step, in decades of amplitude (default 0.02), where no
        :class:`~jointdyn.continuation.ContinuationOptions` is given.
    ds_max : float
        Largest arc-length step (default 0.0625: at most 1/16 decade between points, at least 16
        points per decade), likewise.
    tol : float
        Newton tolerance of an EPMC point on the scaled residual (default 1e-12), likewise; tight
        because the energy balance of a point (self-excitation against dissipation) holds to the
        residual relative to the damping ratio, which is small at small amplitudes.
    start_max_iter : int
        Newton iterations of the first point, from the linear stuck mode (default 30).
    auto_check_points : int
        Points of a backbone (spread over it, plus its largest damping) where ``harmonics="auto"`` or
        ``samples="auto"`` check the discretisation (default 12), in :mod:`jointdyn.modes._auto`.
    """

    ds_start: float = 0.02
    ds_max: float = 0.0625
    tol: float = 1e-12
    start_max_iter: int = 30
    auto_check_points: int = 12

    def __post_init__(self) -> None:
        for name in ("ds_start", "ds_max", "tol"):
            object.__setattr__(self, name, V.positive(name, getattr(self, name)))
        if self.ds_start > self.ds_max:
            raise ValueError(f"ds_start must be in (0, ds_max = {self.ds_max!r}], got {self.ds_start!r}")
        for name in ("start_max_iter", "auto_check_points"):
            object.__setattr__(self, name, V.positive_int(name, getattr(self, name)))


@dataclass(frozen=True)
class QSMAOptions:
    """The quasi-static push's numbers, with their defaults.

    Attributes
    ----------
    steps_per_decade : int
        Backbone points per decade of the output DOF's displacement (default 40).
    decades_below : int
        Decades pushed below the smallest requested amplitude: the work integrals start at zero
        displacement (default 3; >= 1).
    substeps : int
        Push steps per backbone point: the work integrals use every step (their error at a kink of a
        law, e.g. the onset of slip of a Jenkins element, falls as the square of the step), the backbone
        reports every ``substeps``-th (default 4).
    tol : float
        Static equilibrium: Newton converged when max |residual| is at most this times the largest
        elastic or applied force (default 1e-12).
    max_iter : int
        Newton iterations per step (default 50).
    """

    steps_per_decade: int = 40
    decades_below: int = 3
    substeps: int = 4
    tol: float = 1e-12
    max_iter: int = 50

    def __post_init__(self) -> None:
        for name in ("steps_per_decade", "decades_below", "substeps", "max_iter"):
            object.__setattr__(self, name, V.positive_int(name, getattr(self, name)))
        object.__setattr__(self, "tol", V.positive("tol", self.tol))


def epmc_options(value) -> EPMCOptions:
    """``value`` as EPMCOptions: None (the defaults) or EPMCOptions (ValueError naming ``epmc_options``)."""
    if value is None:
        return EPMCOptions()
    if not isinstance(value, EPMCOptions):
        raise ValueError(f"epmc_options must be an EPMCOptions or None (the defaults), got {value!r}")
    return value


def qsma_options(value) -> QSMAOptions:
    """``value`` as QSMAOptions: None (the defaults) or QSMAOptions (ValueError naming ``options``)."""
    if value is None:
        return QSMAOptions()
    if not isinstance(value, QSMAOptions):
        raise ValueError(f"options must be a QSMAOptions or None (the defaults), got {value!r}")
    return value
