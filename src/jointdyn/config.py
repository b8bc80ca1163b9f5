"""Numerical tolerances and defaults, in one place.

Tests import their tolerances from here (``TEST_*``), and solvers their
defaults, so that a change of accuracy policy is one edit.
"""

from __future__ import annotations

# --- contact-law kernels -------------------------------------------------
#: default depth of the reversal-point stack of the closed-form Iwan law
IWAN_MAX_DEPTH = 64
#: relative tolerance used to decide that a branch has reached an earlier
#: reversal point (Masing's extended rules), relative to fy/kt
IWAN_WIPE_RTOL = 1e-12

# --- quasi-static driver --------------------------------------------------
QS_STEPS_PER_CYCLE = 2000
QS_CYCLES = 2

# --- test tolerances (tests/ import these) -------------------------------
#: closed-form energy per cycle vs MODEL.md formula (relative)
TEST_ENERGY_RTOL = 5e-3
#: closed-form Iwan vs discrete (n = 4000), as a fraction of fy
TEST_IWAN_VS_DISCRETE_FY = 5e-3
#: compiled kernels vs plain-Python references (absolute, in units of fy)
TEST_REFERENCE_ATOL_FY = 1e-9
#: energy created over a closed cycle may not exceed this fraction of fy*A
TEST_ENERGY_CREATION_TOL = 1e-9

# --- quasi-static driver and loop metrics (issue 2) ----------------------

# --- time integration and steady state (issue 3) --------------------------

# --- sweeps (issue 3) -----------------------------------------------------

# --- harmonic balance, continuation, stability (issue 4) ------------------
#: bound on the periods marched per AFT evaluation (two normally suffice
#: for Masing-type laws; the force must repeat to HB_PERIODIC_RTOL)
HB_MAX_PASSES = 8
#: two consecutive marched periods agree when max|T_p - T_(p-1)| <= rtol max|T|
HB_PERIODIC_RTOL = 1e-10
#: default harmonics and time samples per period
HB_HARMONICS = 7
HB_SAMPLES = 128
#: Newton: converged when |R| <= rtol * force scale and |dX| <= rtol * (|X| + x scale)
HB_NEWTON_RTOL = 1e-9
HB_NEWTON_MAX_ITER = 12
#: continuation: step-length control (in the scaled unknowns), bounds
HB_DS_MIN = 1e-6
HB_DS_MAX = 0.25
HB_DS_GROW = 1.6
HB_TARGET_NEWTON_ITER = 4
HB_MAX_POINTS = 2000
#: response declared unbounded when q = kt X / fy exceeds this (hard bound)
HB_UNBOUNDED_Q = 1e5
#: describing-function saturation test (MODEL.md section 6, Den Hartog):
#: applied once q exceeds HB_SATURATION_Q, the contact slips at least this
#: fraction of the period and viscous damping is negligible
HB_SATURATION_Q = 30.0
HB_SATURATION_SLIP_FRACTION = 0.9
#: a Floquet exponent with Re(s) > HB_STABILITY_RTOL * w marks instability
HB_STABILITY_RTOL = 1e-6
#: test tolerances
TEST_HB_JACOBIAN_RTOL = 1e-6
TEST_HB_DF_RTOL = 1e-4
TEST_HB_VS_TIME_RTOL = 1e-2
