"""Numerical tolerances and defaults, in one place.

Tests import their tolerances from here (``TEST_*``), and solvers their
defaults, so that a change of accuracy policy is one edit.
"""

from __future__ import annotations

# --- contact-law kernels -------------------------------------------------
#: default depth of the reversal-point stack of the closed-form Iwan law
IWAN_MAX_DEPTH = 64
#: a branch closer than this to an earlier reversal point (normalised
#: displacement kt x / fy) has reached it (Masing rejoin); the force error
#: is of the same order in units of fy
IWAN_WIPE_TOL = 1e-9

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
#: default RK4 steps per forcing period (before events and reversal splits)
TI_STEPS_PER_PERIOD = 256
#: steps per period are raised so that w_max * h <= this (w_max: stiffest
#: linear mode with every contact stuck); RK4 is stable up to ~2.8
TI_MAX_OMEGA_H = 1.0
#: at most this many reversal splits inside one grid step
TI_MAX_SPLITS = 4
#: an event closer than this fraction of a step to a grid point moves it
TI_EVENT_MERGE = 1e-6
#: normal load put at a re-contact instant, as a fraction of n0 (> 0 so that
#: the committed law state is "in contact, virgin at the re-contact point")
TI_RECONTACT_ALPHA = 1e-12
#: a state larger than this factor times (|f|/k_min + fy/kt) is a blow-up
TI_BLOWUP_FACTOR = 1e8
#: steady state: default relative tolerance on the half peak-to-peak
#: amplitude and on the period-boundary state (Poincare points)
SS_AMP_RTOL = 1e-4
#: steady state: default relative tolerance on the energy per period
SS_ENERGY_RTOL = 1e-3
#: steady state: work of the forcing = dissipation per period to this
#: (relative; the energy integrals carry the discretisation error)
SS_BALANCE_RTOL = 1e-2
#: steady state: windows (of p periods) that must agree
SS_CHECK_PERIODS = 3
#: steady state: largest period multiple p looked for
SS_MAX_MULTIPLE = 4
#: steady state: longer multiples (up to this) are detected and reported
#: as "not-settled", detail "period-P", instead of running to max_periods
SS_DETECT_MULTIPLE = 12
#: steady state: a multiple p > 1 is accepted only when the largest
#: one-period mismatch over the last K p periods is at least this fraction
#: of that over the K p periods before (no decaying beat)
SS_MULTIPLE_DECAY = 0.97
#: steady state: after shooting, stop as "quasi-periodic-or-chaotic" when
#: the largest one-period mismatch over the last SS_STALL_PERIODS/2 periods
#: is >= SS_STALL_RATIO times that over the half before
SS_STALL_PERIODS = 240
SS_STALL_RATIO = 0.9
#: steady state: default cap on integrated periods
SS_MAX_PERIODS = 1500
#: steady state: periods integrated between two checks
SS_CHUNK = 8
#: steady state: shooting (Newton on the period map) when the estimated
#: number of periods to converge exceeds this
SS_SHOOT_AFTER = 40
#: steady state: Newton iterations of one shooting attempt
SS_SHOOT_MAXIT = 12
#: steady state: largest Newton step (relative to the amplitude) and
#: step halvings of the line search
SS_SHOOT_MAXSTEP = 1.0
SS_SHOOT_HALVINGS = 8
#: steady state: before shooting (section at phase 0), rebuild the law
#: states from the last period alone (forget the transient's memory)
SS_SHOOT_CLEAN_STATE = True
#: steady state: shooting attempts per run
SS_MAX_SHOTS = 3
#: steady state: relative finite-difference step of the monodromy matrix
SS_SHOOT_FD = 1e-6
#: steady state: a Floquet multiplier above 1 + this marks an unstable orbit
SS_FLOQUET_TOL = 1e-3
#: steady state: describing-function iterations of the linear start
SS_LINEAR_ITERS = 30
#: relative change of the describing-function amplitude that ends that
#: iteration (it only seeds the integration, which does the rest)
SS_LINEAR_RTOL = 1e-2
#: unbounded: amplitude increasing over this many consecutive periods ...
SS_GROWTH_PERIODS = 40
#: ... with increments of the second half >= this fraction of the first
SS_GROWTH_RATIO = 0.9
#: ... and with the amplitude of x[response_dof] above this many fy/kt of
#: the first contact (friction saturated: only then can friction lose)
SS_UNBOUNDED_Q = 20.0

# --- test tolerances for time integration (tests/test_dynamics.py) --------
#: peak of the beta = 1000 response vs sqrt((k + kt)/k)
TEST_TI_PEAK_GAMMA_ATOL = 0.01
#: eta = 0 tiny forcing vs linear (k + kt) oscillator, relative
TEST_TI_LINEAR_RTOL = 0.01
#: energy balance W = E_contact + E_viscous at steady state, relative
TEST_TI_ENERGY_RTOL = 0.01
#: amplitude change when the step is halved at the default steps, relative
TEST_TI_STEP_HALVING_RTOL = 0.005
#: compiled law inside the integrator vs drivers.march, in units of fy
TEST_TI_MARCH_ATOL_FY = 1e-9

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
#: bound on the periods marched per AFT evaluation (two normally suffice
#: for Masing-type laws; the force must repeat to HB_PERIODIC_RTOL)
HB_MAX_PASSES = 8
#: two consecutive marched periods agree when max|T_p - T_(p-1)| <= rtol max|T|
HB_PERIODIC_RTOL = 1e-10
#: default harmonics and time samples per period
HB_HARMONICS = 7
HB_SAMPLES = 128
#: Newton: converged when max|R| <= this, R scaled by max(F1, fy) (damped Newton)
HB_NEWTON_RTOL = 1e-9
HB_NEWTON_MAX_ITER = 12
#: continuation: step-length control (in the scaled unknowns), bounds
HB_DS_MIN = 1e-6
HB_DS_MAX = 0.1
HB_DS_GROW = 1.6
HB_TARGET_NEWTON_ITER = 4
HB_MAX_POINTS = 2000
#: response declared unbounded when q = kt X / fy exceeds this (hard bound)
HB_UNBOUNDED_Q = 1e5
#: describing-function saturation test (MODEL.md section 6, Den Hartog):
#: applied once q exceeds HB_SATURATION_Q, when the contact slips at least
#: this fraction of the period and C = 0 (single DOF)
HB_SATURATION_Q = 30.0
HB_SATURATION_SLIP_FRACTION = 0.9
#: a Floquet exponent with Re(s) > HB_STABILITY_RTOL * w marks instability
HB_STABILITY_RTOL = 1e-6
#: test tolerances
TEST_HB_JACOBIAN_RTOL = 1e-6
TEST_HB_DF_RTOL = 1e-4
TEST_HB_VS_TIME_RTOL = 1e-2
#: turning points of a branch (secant): dead band as a fraction of the range
HB_TURNING_BAND = 5e-4
