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
#: default CLI gamma grid START:STOP:STEP (the paper's Fig 6 range)
SWEEP_GAMMA_DEFAULT = (0.6, 1.8, 0.01)
#: local pool for sweep lines when no Dask client is given: "process" or
#: "thread" (numba kernels release the GIL; see the report for the measurement)
SWEEP_POOL = "process"
#: status codes of a swept point (netCDF-friendly int8); index = code
SWEEP_STATUS = ("periodic", "not-settled", "unbounded")
#: code of a point that was not computed (never written by a finished sweep)
SWEEP_STATUS_MISSING = -1

# --- harmonic balance, continuation, stability (issue 4) ------------------
