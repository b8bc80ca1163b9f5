"""Harmonic balance for jointdyn systems: AFT with exact forward-mode
Jacobians, arc-length continuation (:mod:`jointdyn.continuation`) in a
parameter object (:mod:`jointdyn.hb.parameters`), Hill stability,
unbounded-response detection, per-DOF forcing phases, and exact
condensation onto the contact DOFs for large structures
(:mod:`jointdyn.hb.condense`; see docs/harmonic-balance.md)."""

from .condense import CondensedHBProblem, Receptance, make_problem, receptance
from .frc import HBBranch, HBPeak, HBSolution, PointStatus, branch_dataset, continue_hb, frc_hb, harmonic_balance
from .parameters import DELTA, ETA, F1, GAMMA, N0, PARAMETERS, HBParameter, SystemParameter, parameter_named
from .problem import HBProblem
from .monodromy import monodromy_multipliers
from .stability import hill_exponents, hill_growth, hill_stability

__all__ = [
    "frc_hb",
    "continue_hb",
    "harmonic_balance",
    "HBSolution",
    "branch_dataset",
    "HBBranch",
    "HBPeak",
    "PointStatus",
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
    "monodromy_multipliers",
]
