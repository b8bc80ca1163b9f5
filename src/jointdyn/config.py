"""The numbers jointdyn's packages share, one section per package in the order of the layers, bottom up:
contact laws; systems and system files; memory bounds; continuation and the quasi-static driver; the time
march and its steady states; harmonic balance; nonlinear modes; identification; sweeps.

A number that one solver or package alone reads belongs in that solver's options object
(``ContinuationOptions``, ``LinearSolveOptions``, ``SweepOptions``, ``StabilityOptions``,
``RingdownOptions``) or in its module, with its default documented there; ``tests/test_architecture.py``
fails on a number here that one package alone reads. Test tolerances live with the tests
(``tests/tolerances.py``). Units are given where a number has one; "relative" numbers are fractions of the
scale named.
"""

from __future__ import annotations

# --- contact-law models ------------------------------------------------------
#: registered name of the contact law every front end uses when none is
#: given (CLI ``--model``, ``System.paper_damper``, sweeps, figures): the
#: exact Iwan model with varying normal load
MODEL = "iwan"
#: Jenkins elements of the discrete Iwan model
LAW_DISCRETE_N = 1000
#: microslip exponent chi of Segalman's four-parameter Iwan law (``segalman``)
#: when none is given: the slip-displacement density grows as phi^chi
SEGALMAN_CHI = -0.5

# --- systems (jointdyn.systems) ---------------------------------------------------------
#: eigenvalues of (M, K_reference) below this fraction of the largest are
#: rigid-body modes (zero up to rounding), skipped by the default w0
SYSTEM_RIGID_MODE_RTOL = 1e-10
#: structures of up to this many DOFs are checked (M positive definite, K and C positive
#: semi-definite) and get their w0 from dense eigen-decompositions; larger ones from a
#: Cholesky factorisation (shifted by the semi-definiteness tolerance) and Lanczos iterations
#: for the extreme eigenvalues (scipy.sparse.linalg.eigsh), which scale to config.FILES_MAX_DOF
SYSTEM_DENSE_CHECK_MAX_DOF = 1000

# --- system files (jointdyn.files) ------------------------------------------------------
#: most degrees of freedom of a matrix read from a system file (its dense
#: float64 copy takes 8 n^2 bytes: 800 MB at the bound)
FILES_MAX_DOF = 10_000
#: most node pairs of one interface, however given (inline, a pairs CSV file, the library): every
#: solver evaluates each pair at every sample of every step, so the time grows with the pairs (an HB
#: branch of 2000 pairs with H = 1 and 8 samples took 40 s of CPU, 29 ms an evaluation, measured
#: 2026-12); a pair against ground takes 3 DOFs, so FILES_MAX_DOF DOFs hold 3333 pairs on distinct nodes
INTERFACE_MAX_PAIRS = 5_000

# --- memory bounds (jointdyn._validate.memory_budget) ------------------------------------
#: bound on the memory one computation may allocate, bytes; None: MEMORY_FRACTION of the
#: memory available when it is checked (MemAvailable of /proc/meminfo, else the physical memory).
#: Sizes given as options or parameters (harmonics, samples, steps per period, law state sizes) are
#: refused before computing when their estimated arrays exceed it
MEMORY_LIMIT_BYTES = None
#: share of the available memory a computation may take when MEMORY_LIMIT_BYTES is None
MEMORY_FRACTION = 0.5

# --- continuation (jointdyn.continuation; unknowns, parameter and residual scaled) ----
# The step control and the linear solves have their numbers in ContinuationOptions and
# LinearSolveOptions (jointdyn.continuation.options); here only those the solvers share with it.
#: Newton converged when max|R| <= this (scaled residual; harmonic balance
#: scales R by max(F1, fy)): ContinuationOptions.tol, and harmonic balance's single solutions
CONT_TOL = 1e-9
#: from this many unknowns, a walk's bordered systems are solved by GMRES
#: preconditioned with the LU factors of an earlier matrix of the walk, and
#: factorised anew only when that fails (jointdyn.continuation.linalg): a
#: factorisation costs seconds there (benchmarks/bench_linalg.py); harmonic balance and EPMC
#: choose the form of their Jacobians (sparse, blocks, dense) by the same bound
CONT_KRYLOV_SOLVE = 2000
#: from CONT_KRYLOV_SOLVE unknowns, a walk whose first matrix has at most this
#: fraction of nonzero entries factorises by SuperLU (scipy.sparse.linalg.splu)
#: at every solve (the 60-node chain of benchmarks/bench_hb_interface_chain.py,
#: 1980 unknowns, 0.7 % nonzero: 4 ms against 227 ms for dense LAPACK); harmonic balance
#: evaluates its Jacobian as a sparse matrix below the same density
CONT_SPARSE_DENSITY = 0.02

# --- quasi-static driver -------------------------------------------------------
#: uniform samples per cycle of the harmonic history
QS_STEPS_PER_CYCLE = 2000
#: cycles of the harmonic history
QS_CYCLES = 2
#: most samples of a harmonic history (cycles x steps per cycle); bounds the
#: memory of one loop (about 100 bytes per sample with its CSV output)
QS_MAX_SAMPLES = 10_000_000
#: a time within this fraction of a step (harmonic grid) or of the history
#: duration (cycle windows) is the same instant: crossing instants and cycle
#: boundaries snap onto existing samples instead of creating tiny steps
QS_SNAP_RTOL = 1e-9

# --- monodromy (finite-difference Floquet multipliers of the period map) --------------
#: periods, and samples per period, of the harmonic-balance displacement over
#: which each contact law is marched to obtain its state at the section
MONODROMY_WARM_PERIODS = 3
MONODROMY_WARM_SAMPLES = 4096

# --- harmonic balance: discretisation and AFT ------------------------------------------
#: harmonics 0..H of the unknowns
HB_HARMONICS = 7
#: AFT time samples per period
HB_SAMPLES = 128
#: ``harmonics="auto"`` / ``samples="auto"`` (the defaults of HB branches): start at HB_HARMONICS and
#: HB_SAMPLES; every refined peak is solved again with 2H + 1 harmonics and with 2 Ns samples, and the
#: discretisation is refined (and the branch computed again) while a peak amplitude changes by more
#: than this fraction of the highest peak's
HB_AUTO_RTOL = 1e-3
#: bound on the periods marched per AFT evaluation (two normally suffice
#: for Masing-type laws; the force must repeat to jointdyn.hb._aft.HB_PERIODIC_RTOL)
HB_MAX_PASSES = 8

# --- nonlinear modes (jointdyn.modes) ------------------------------------------------
#: default amplitude range of a backbone (first-harmonic amplitude of the
#: output DOF), in units of fy / kt of the first contact: from deep in the
#: stuck regime to well into macroslip (four decades)
MODES_AMPLITUDE_Q = (1e-2, 1e2)

# --- identification (jointdyn.identify) -------------------------------------------
# The fits' numbers are constants of the modules that read them (jointdyn.identify._lsq,
# _profile, loops, backbone) and the ring-down's are RingdownOptions fields; here only the
# input bounds that the fit command checks too.
#: most data rows of a loop fit (``fit --input``): the least squares evaluates the law over every sample
#: some hundred times; 1e6 samples took 6 s of CPU time (measured, 2026-12)
FIT_MAX_LOOP_SAMPLES = 1_000_000
#: most points of a backbone fit (``fit --backbone``): every point costs a describing function per
#: evaluation, 4 ms of CPU time per point for the whole fit (1000 points took 3.8 s, measured 2026-12)
FIT_MAX_BACKBONE_POINTS = 1_000

# --- sweeps --------------------------------------------------------------------------
#: why a swept point is not-settled (``not_settled_reason``; index = code, 0
#: for every other point): still converging at the period budget, stalled
#: (quasi-periodic or chaotic), or repeating only after more than
#: SS_MAX_MULTIPLE periods
SWEEP_NOT_SETTLED_REASONS = ("none", "slowly-converging", "quasi-periodic-or-chaotic", "long-period")
