"""Harmonic balance for jointdyn systems: AFT with exact forward-mode
Jacobians, arc-length continuation (:mod:`jointdyn.continuation`) in a
parameter object (:mod:`jointdyn.hb.parameters`), Hill stability,
unbounded-response detection, per-DOF forcing phases, and exact
condensation onto the contact DOFs for large structures
(:mod:`jointdyn.hb.condense`; see docs/harmonic-balance.md).

Read top to bottom: the entry points (:mod:`~jointdyn.hb.frc`), the
Dataset export (:mod:`~jointdyn.hb.export`), the automatic choice of
harmonics and samples (:mod:`~jointdyn.hb.discretisation`) from one
validated request (:mod:`~jointdyn.hb.levels`), one branch at a
fixed discretisation (:mod:`~jointdyn.hb.branch`), the result types
(:mod:`~jointdyn.hb.results`), then the problem (:mod:`~jointdyn.hb.problem`,
:mod:`~jointdyn.hb.condense`, :mod:`~jointdyn.hb.parameters`) and its
evaluation (:mod:`~jointdyn.hb._aft`, :mod:`~jointdyn.hb.stability`,
:mod:`~jointdyn.hb.monodromy`)."""

from .condense import CondensedHBProblem, Receptance, make_problem, receptance
from .export import branch_dataset, discretisation_attrs
from .frc import check_mean_position, continue_hb, frc_hb, harmonic_balance
from .levels import AUTO, Discretisation, Level, check_memory, hb_bytes
from .parameters import DELTA, ETA, F1, GAMMA, N0, PARAMETERS, HBParameter, SystemParameter, parameter_named
from .problem import HBProblem
from .monodromy import monodromy_multipliers
from .options import HBOptions
from .results import DiscretisationCheck, HBBranch, HBPeak, HBSolution, PointStatus, SolveStatus
from .stability import hill_exponents, hill_growth, hill_stability
from .stability_options import StabilityOptions

__all__ = [
    "frc_hb",
    "continue_hb",
    "harmonic_balance",
    "HBSolution",
    "branch_dataset",
    "discretisation_attrs",
    "DiscretisationCheck",
    "AUTO",
    "Level",
    "Discretisation",
    "check_memory",
    "hb_bytes",
    "check_mean_position",
    "HBBranch",
    "HBPeak",
    "PointStatus",
    "SolveStatus",
    "HBProblem",
    "CondensedHBProblem",
    "make_problem",
    "receptance",
    "Receptance",
    "HBParameter",
    "SystemParameter",
    "PARAMETERS",
    "GAMMA",
    "F1",
    "ETA",
    "N0",
    "DELTA",
    "parameter_named",
    "hill_exponents",
    "hill_stability",
    "hill_growth",
    "hill_arnoldi_exponents",
    "hill_arnoldi_growth",
    "ArnoldiExponents",
    "StabilityOptions",
    "HBOptions",
    "monodromy_multipliers",
]


#: names of the Arnoldi stability module, imported on first use (a process that never asks for Arnoldi
#: stability does not import it: fresh-process start-up time)
_LAZY = {"ArnoldiExponents", "hill_arnoldi_exponents", "hill_arnoldi_growth"}


def __getattr__(name):
    if name in _LAZY:
        from . import hill_arnoldi

        return getattr(hill_arnoldi, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
