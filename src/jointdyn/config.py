"""Numerical defaults of jointdyn, grouped by subject.

Solvers and front ends (CLI, sweeps, figures) read their defaults from here
and nowhere else, so that a change of accuracy policy is one edit. Test
tolerances live with the tests (``tests/tolerances.py``). Units are given
where a number has one; "relative" numbers are fractions of the scale named.
"""

from __future__ import annotations

# --- contact-law models ------------------------------------------------------
#: Jenkins elements of the discrete Iwan model
LAW_DISCRETE_N = 1000
#: capacity of the reversal-point stack of the closed-form Iwan law
IWAN_MAX_DEPTH = 64
#: a branch closer than this to an earlier reversal point (normalised
#: displacement kt x / fy) has reached it (Masing rejoin); the force error
#: is of the same order in units of fy
IWAN_WIPE_TOL = 1e-9

# --- quasi-static driver -------------------------------------------------------
#: uniform samples per cycle of the harmonic history
QS_STEPS_PER_CYCLE = 2000
#: cycles of the harmonic history
QS_CYCLES = 2
#: most samples of a harmonic history (cycles x steps per cycle); bounds the
#: memory of one loop (about 100 bytes per sample with its CSV output)
QS_MAX_SAMPLES = 10_000_000
#: a cycle of a sampled history spans at least this many sample intervals on
#: average (fewer is not a sampled loop); bounds the cycles of --period
QS_MIN_INTERVALS_PER_CYCLE = 2
#: a time within this fraction of a step (harmonic grid) or of the history
#: duration (cycle windows) is the same instant: crossing instants and cycle
#: boundaries snap onto existing samples instead of creating tiny steps
QS_SNAP_RTOL = 1e-9
#: load (as a fraction of n_ref) at which a law is evaluated at a re-contact
#: instant (N = 0 followed by N > 0), so that the virgin curve starts exactly
#: there; the sample is reported as separated with T = 0
QS_RECONTACT_LOAD = 1e-300

# --- time integration (explicit RK4 with events) --------------------------------
#: RK4 steps per forcing period (before events and reversal splits)
TI_STEPS_PER_PERIOD = 256
#: steps per period are raised so that w_max * h <= this (w_max: stiffest
#: linear mode with every contact stuck); RK4 is stable up to ~2.8
TI_MAX_OMEGA_H = 1.0
#: once a normal spring opens, the steps are refined so that w_max * h <=
#: this (w_max with the springs closed): every re-contact sets the normal
#: DOFs ringing at their own frequency, and RK4 at w h = 1 damps that
#: ringing numerically by about 0.3 % of its energy per step, which shows in
#: the energy balance (measured on the coupled paper damper, eta 1.5: 6e-3
#: at w h = 0.85, 2e-6 at 0.21)
TI_SPRING_OMEGA_H = 0.3
#: at most this many reversal splits inside one grid step
TI_MAX_SPLITS = 4
#: an event closer than this fraction of a step to a grid point moves it
TI_EVENT_MERGE = 1e-6
#: normal load put at a re-contact instant, as a fraction of n0 (> 0 so that
#: the committed law state is "in contact, virgin at the re-contact point")
TI_RECONTACT_ALPHA = 1e-12
#: a state larger than this factor times (|f|/k_min + fy/kt) is a blow-up
TI_BLOWUP_FACTOR = 1e8

# --- steady state: periodicity checks ----------------------------------------------
#: relative tolerance on the half peak-to-peak amplitude and on the
#: period-boundary state (Poincare points)
SS_AMP_RTOL = 1e-4
#: relative tolerance on the energy per period
SS_ENERGY_RTOL = 1e-3
#: work of the forcing = dissipation per period to this (relative; the
#: energy integrals carry the discretisation error)
SS_BALANCE_RTOL = 1e-2
#: windows (of p periods) that must agree
SS_CHECK_PERIODS = 3
#: largest period multiple p accepted as a periodic steady state
SS_MAX_MULTIPLE = 4
#: longer multiples (up to this) are detected and reported as
#: "not-settled", detail "period-P", instead of running to max_periods
SS_DETECT_MULTIPLE = 12
#: a multiple p > 1 is accepted only when the largest one-period mismatch
#: over the last K p periods is at least this fraction of that over the
#: K p periods before (no decaying beat)
SS_MULTIPLE_DECAY = 0.97
#: after shooting, stop as "quasi-periodic-or-chaotic" when the largest
#: one-period mismatch over the last SS_STALL_PERIODS/2 periods is >=
#: SS_STALL_RATIO times that over the half before
SS_STALL_PERIODS = 240
SS_STALL_RATIO = 0.9
#: cap on integrated periods
SS_MAX_PERIODS = 1500
#: periods integrated between two checks
SS_CHUNK = 8

# --- steady state: start and shooting ------------------------------------------------
#: describing-function iterations of the linear start
SS_LINEAR_ITERS = 30
#: relative change of the describing-function amplitude that ends that
#: iteration (it only seeds the integration, which does the rest)
SS_LINEAR_RTOL = 1e-2
#: shooting (Newton on the period map) when the estimated number of
#: periods to converge exceeds this
SS_SHOOT_AFTER = 40
#: Newton iterations of one shooting attempt
SS_SHOOT_MAXIT = 12
#: largest Newton step (relative to the amplitude) and step halvings of the
#: line search
SS_SHOOT_MAXSTEP = 1.0
SS_SHOOT_HALVINGS = 8
#: before shooting (section at phase 0), rebuild the law states from the
#: last period alone (forget the transient's memory)
SS_SHOOT_CLEAN_STATE = True
#: shooting attempts per run
SS_MAX_SHOTS = 3
#: relative finite-difference step of the monodromy matrix
SS_SHOOT_FD = 1e-6
#: a Floquet multiplier above 1 + this marks an unstable orbit
SS_FLOQUET_TOL = 1e-3

# --- monodromy (finite-difference Floquet multipliers of the period map) --------------
#: relative central-difference step of the monodromy check of harmonic-balance
#: solutions (of the amplitude for displacements, of w times it for velocities)
MONODROMY_FD_STEP = 1e-6
#: periods, and samples per period, of the harmonic-balance displacement over
#: which each contact law is marched to obtain its state at the section
MONODROMY_WARM_PERIODS = 3
MONODROMY_WARM_SAMPLES = 4096

# --- steady state: unbounded response ----------------------------------------------
#: amplitude increasing over this many consecutive periods ...
SS_GROWTH_PERIODS = 40
#: ... with increments of the second half >= this fraction of the first
SS_GROWTH_RATIO = 0.9
#: ... and with the amplitude of x[response_dof] above this many fy/kt of
#: the first contact (friction saturated: only then can friction lose)
SS_UNBOUNDED_Q = 20.0

# --- sweeps --------------------------------------------------------------------------
#: gamma grid START:STOP:STEP (the paper's Fig 6 range)
SWEEP_GAMMA_DEFAULT = (0.6, 1.8, 0.01)
#: most points of a gamma grid given as START:STOP:STEP
SWEEP_MAX_GAMMA_POINTS = 100_000
#: seconds to wait for a Dask scheduler to answer (--scheduler)
SWEEP_SCHEDULER_TIMEOUT_S = 5.0
#: local pool for sweep lines when no Dask client is given: "process" or
#: "thread" (the compiled kernels release the GIL)
SWEEP_POOL = "process"
#: status codes of a swept point (netCDF-friendly int8); index = code
SWEEP_STATUS = ("periodic", "not-settled", "unbounded")
#: code of a point that was not computed (never written by a finished sweep)
SWEEP_STATUS_MISSING = -1

# --- harmonic balance: discretisation and AFT ------------------------------------------
#: harmonics 0..H of the unknowns
HB_HARMONICS = 7
#: AFT time samples per period
HB_SAMPLES = 128
#: bound on the periods marched per AFT evaluation (two normally suffice
#: for Masing-type laws; the force must repeat to HB_PERIODIC_RTOL)
HB_MAX_PASSES = 8
#: two consecutive marched periods agree when max|T_p - T_(p-1)| <= rtol max|T|
HB_PERIODIC_RTOL = 1e-10

# --- harmonic balance: Newton and continuation ---------------------------------------
#: Newton converged when max|R| <= this, R scaled by max(F1, fy)
HB_NEWTON_RTOL = 1e-9
#: Newton iterations per correction
HB_NEWTON_MAX_ITER = 12
#: arc-length step (scaled unknowns): first, smallest, largest
HB_DS_START = 0.05
HB_DS_MIN = 1e-6
HB_DS_MAX = 0.1
#: step growth factor after an easy correction
HB_DS_GROW = 1.6
#: Newton iterations aimed at per correction (step control)
HB_TARGET_NEWTON_ITER = 4
#: bound on the points of a branch
HB_MAX_POINTS = 2000

# --- harmonic balance: classification of points ---------------------------------------
#: response declared unbounded when q = kt X / fy exceeds this (hard bound)
HB_UNBOUNDED_Q = 1e5
#: describing-function saturation test (Den Hartog): applied once q exceeds
#: HB_SATURATION_Q, when the contact slips at least this fraction of the
#: period and C = 0 (single DOF)
HB_SATURATION_Q = 30.0
HB_SATURATION_SLIP_FRACTION = 0.9
#: a Floquet exponent with Re(s) > HB_STABILITY_RTOL * w marks instability
HB_STABILITY_RTOL = 1e-6
#: turning points of a branch (secant): dead band as a fraction of the range
HB_TURNING_BAND = 5e-4
