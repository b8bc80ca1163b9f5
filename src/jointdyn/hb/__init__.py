"""Harmonic balance for jointdyn systems: AFT with exact forward-mode
Jacobians, arc-length continuation, Hill stability, unbounded-response
detection (see docs/harmonic-balance.md)."""

from .continuation import ContinuationResult, continuation, newton, turning_points
from .frc import HBBranch, HBSolution, branch_dataset, continue_hb, frc_hb, harmonic_balance
from .problem import PARAMETERS, HBProblem
from .monodromy import monodromy_multipliers
from .stability import hill_exponents, hill_growth, hill_stability

__all__ = [
    "frc_hb",
    "continue_hb",
    "harmonic_balance",
    "HBSolution",
    "branch_dataset",
    "HBBranch",
    "HBProblem",
    "PARAMETERS",
    "continuation",
    "newton",
    "turning_points",
    "ContinuationResult",
    "hill_exponents",
    "hill_stability",
    "hill_growth",
    "monodromy_multipliers",
]
