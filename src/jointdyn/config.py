"""Numerical tolerances and defaults, in one place.

Tests import their tolerances from here (``TEST_*``), and solvers their
defaults, so that a change of accuracy policy is one edit.
"""

from __future__ import annotations

# --- contact-law kernels -------------------------------------------------
#: default depth of the reversal-point stack of the closed-form Iwan law
IWAN_MAX_DEPTH = 64

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
#: a time within this fraction of a step (harmonic grid) or of the history
#: duration (cycle windows) is the same instant: crossing instants and cycle
#: boundaries snap onto existing samples instead of creating tiny steps
QS_SNAP_RTOL = 1e-9
#: load (as a fraction of n_ref) at which a law is evaluated at a re-contact
#: instant (N = 0 followed by N > 0), so that the virgin curve starts exactly
#: there; the sample is reported as separated with T = 0
QS_RECONTACT_LOAD = 1e-300
#: test: exactness of the separation time fraction with crossings inserted
TEST_QS_FRACTION_ATOL = 1e-9
#: test: closed-form Iwan vs discrete (n = 1000) energy per cycle at constant
#: N, relative (discretisation error of the ground truth is O(1/n^2))
TEST_QS_DISCRETE_ENERGY_RTOL = 5e-3
#: contact-law tests: tangent kT of compiled kernels vs plain-Python
#: references (absolute, in units of kt)
TEST_REFERENCE_ATOL_KT = 1e-9
#: contact-law tests: step_jvp vs central finite differences of the march
#: (relative to the largest derivative of the history)
TEST_JVP_RTOL = 1e-6
#: contact-law tests: finite-difference step, relative to the history's scale
TEST_JVP_FD_STEP = 1e-6
#: contact-law tests: |T| <= alpha fy (1 + this) (rounding of the clip)
TEST_FORCE_BOUND_RTOL = 1e-12

# --- time integration and steady state (issue 3) --------------------------

# --- sweeps (issue 3) -----------------------------------------------------

# --- harmonic balance, continuation, stability (issue 4) ------------------
