"""Test tolerances, in one place (they belong to the tests, not to the package).

Each constant says what it bounds and in which units.
"""

# --- contact laws ----------------------------------------------------------
#: closed-form energy per cycle vs the formula (relative)
TEST_ENERGY_RTOL = 5e-3
#: closed-form Iwan (iwan-closed) vs discrete (n = 4000) at constant load, as a fraction of fy
TEST_IWAN_VS_DISCRETE_FY = 5e-3
#: compiled kernels vs plain-Python references (absolute, in units of fy)
TEST_REFERENCE_ATOL_FY = 1e-9
#: tangent kT of compiled kernels vs plain-Python references (absolute, in units of kt)
TEST_REFERENCE_ATOL_KT = 1e-9
#: energy created over a closed cycle may not exceed this fraction of fy*A
TEST_ENERGY_CREATION_TOL = 1e-9
#: step_jvp vs central finite differences of the march (relative to the
#: largest derivative of the history)
TEST_JVP_RTOL = 1e-6
#: finite-difference step, relative to the history's scale
TEST_JVP_FD_STEP = 1e-6
#: |T| <= alpha fy (1 + this) (rounding of the clip)
TEST_FORCE_BOUND_RTOL = 1e-12

# --- quasi-static driver ---------------------------------------------------
#: exactness of the separation time fraction with crossings inserted
TEST_QS_FRACTION_ATOL = 1e-9

# --- time integration --------------------------------------------------------
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
#: error ratio when the RK4 step is halved on a smooth problem (fourth
#: order: 16; the range allows for the higher-order terms at the coarsest step)
TEST_TI_ORDER_RATIO = (13.0, 19.0)
#: smooth 2-DOF problem at 512 steps per period vs the DOP853 reference,
#: relative to the largest displacement (measured 4e-9)
TEST_TI_REFERENCE_RTOL = 1e-8
#: monodromy matrix of a linear system (RK4 period map, central differences)
#: vs the exact matrix exponential, relative to its largest entry
TEST_MONODROMY_LINEAR_RTOL = 1e-6

# --- harmonic balance ----------------------------------------------------------
#: exact Jacobian vs central finite differences (relative to max |J|)
TEST_HB_JACOBIAN_RTOL = 1e-6
#: one harmonic vs the describing function (relative)
TEST_HB_DF_RTOL = 1e-4
#: harmonic balance vs time-domain steady state (relative)
TEST_HB_VS_TIME_RTOL = 1e-2

# --- exact Iwan law (iwan) ---------------------------------------------------
#: compiled kernel vs the plain-Python reference (absolute, units of fy / kt)
TEST_EXACT_REFERENCE_ATOL_FY = 1e-12
TEST_EXACT_REFERENCE_ATOL_KT = 1e-12
#: exact law vs the full-memory closed form at constant normal load (both
#: exact there; absolute, units of fy)
TEST_EXACT_CLOSED_FORM_ATOL_FY = 1e-12
#: discrete model (n = 4000) vs the exact law under varying load with
#: separation (its discretisation error, O(1/n^2); units of fy)
TEST_EXACT_DISCRETE_4000_FY = 1e-6
#: the error of the discrete model must shrink by at least this factor per
#: doubling of n (4 for O(1/n^2), 2 for O(1/n); measured 3.2 to 6.0)
TEST_EXACT_DISCRETE_RATIO = 2.5
#: force error of the merges at the default capacity on the Fig 4 loops
#: (units of fy; measured 3.4e-6, docs/exact-iwan.md)
TEST_EXACT_MERGE_FY = 1e-5
#: loop area vs the describing-function energy (relative; trapezoid rule at
#: 4000 samples per cycle)
TEST_EXACT_ENERGY_RTOL = 1e-5

# --- energy balance of steady states ------------------------------------------
#: rounding floor of a period's contact dissipation (units of fy x_slip, the
#: contact's energy scale): added to the point's energy-balance residual
TEST_DISSIPATION_FLOOR = 1e-12
#: harmonic-balance branches: largest distance between the straight line
#: joining two reported points and the curve, in the plane (gamma, ln q)
#: (0.01: 1 % of the amplitude; issue 9)
TEST_HB_CHORD_TOL = 1e-2
