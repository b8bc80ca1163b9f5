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
#: stuck (mu huge) and slipping (mu tiny) limits vs the exact linear FRF with
#: forcing phases (relative to the largest first-harmonic coefficient)
TEST_HB_LINEAR_LIMIT_RTOL = 1e-9
#: condensed vs uncondensed harmonic balance (relative to the largest coefficient)
TEST_HB_CONDENSED_RTOL = 1e-9
#: harmonic balance with a normal spring vs the time-domain steady state,
#: relative to the amplitude (issue 10: 0.5 %; measured 2e-8 closed, H = 7,
#: 256 samples; with separation 4.0e-5, 1.6e-4, 4.7e-4 at gamma 0.8, 1.0,
#: 1.3, H = 15, 512 samples)
TEST_HB_SPRING_VS_TIME_RTOL = 5e-3
#: two Newton solutions of the same equations (mixed laws vs each law alone,
#: a branch point vs a single point), relative to the largest coefficient
TEST_HB_MIXED_RTOL = 1e-6
#: one-harmonic balance of a Jenkins contact with an in-phase normal load vs
#: the quadrature of the exact loop (relative to the amplitude)
TEST_HB_YCM_RTOL = 1e-6

# --- sweeps: per-DOF and per-contact outputs ------------------------------------
#: per-DOF amplitude and offset of the recorded period vs the solver's own
#: (Hermite extremum and quadrature vs RK4 integral), relative to the amplitude
TEST_SWEEP_SAME_RTOL = 1e-6
#: per-contact energy (trapezoid of T du over the steps) vs the solver's
#: total contact energy, relative, at the default steps per period
TEST_SWEEP_CONTACT_ENERGY_RTOL = 5e-4
#: largest normal force over the samples vs the prescribed peak, relative
TEST_SWEEP_NORMAL_EXTREME_RTOL = 1e-4
#: time mean of max(0, N) over the steps vs the exact mean, relative
TEST_SWEEP_NORMAL_MEAN_RTOL = 1e-4

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

# --- normal springs (normal load from the structure) ---------------------------
#: light normal DOF driven by eta n0 sin(w t + delta) vs the prescribed load
#: n0 (1 + eta sin(w t + delta)), relative (issue 10: 0.5 %; measured up to
#: 6.7e-4 in amplitude, 1.6e-3 in contact dissipation: the normal DOF's
#: dynamic amplification 1 / (1 - (w / w_n)^2) = 1 + 1.3e-3 at gamma 1)
TEST_SPRING_PRESCRIBED_RTOL = 5e-3
#: fully stuck / fully slipping contacts on a closed spring vs the linear
#: FRF, relative to the largest amplitude (issue 10; measured 1.4e-7)
TEST_SPRING_LINEAR_RTOL = 1e-5
#: energy balance W = E_contact + E_viscous over a steady period of the
#: coupled damper, relative to W (issue 10; measured up to 6.3e-5)
TEST_SPRING_ENERGY_RTOL = 1e-4
#: integrator at 2000 steps per period vs the event-located plain reference
#: through separation and re-contact, relative to each DOF's largest
#: displacement (measured 1.1e-4 tangential, 3.0e-7 normal; 6.3e-4, 3.2e-4,
#: 1.1e-4, 3.9e-5 tangential at 256, 1000, 2000, 4000 steps: slower than the
#: closed cases, because the normal DOF bounces five times between 1.07 and
#: 1.27 periods and the tangential DOF, lightly damped, carries the phase
#: error of each bounce)
TEST_SPRING_REFERENCE_RTOL = 3e-4
#: two decoupled subsystems with different laws in one system vs each alone
#: (same step grid but for the other part's event splits; measured 3e-10)
TEST_MIXED_DECOUPLED_RTOL = 1e-8

# --- Craig-Bampton reduction -------------------------------------------------------
#: every interior mode kept: reduced vs full model (frequencies, MAC, time
#: response, steady state), relative (rounding; measured 3e-14)
TEST_CB_FULL_RTOL = 1e-9

# --- energy balance of steady states ------------------------------------------
#: rounding floor of a period's contact dissipation (units of fy x_slip, the
#: contact's energy scale): added to the point's energy-balance residual
TEST_DISSIPATION_FLOOR = 1e-12

# --- nonlinear modes (jointdyn.modes) --------------------------------------------
#: one-harmonic EPMC vs the describing function of the exact loop (relative;
#: the AFT's trapezoidal projection of the kinked force converges as
#: 1/samples^2: measured 4e-7 for Jenkins at 4096 samples, 7e-10 for Iwan)
TEST_MODES_DF_RTOL = 1e-6
#: damping ratio from xi vs the contact (and viscous) dissipation per cycle
#: (relative; measured below 1e-9 with the modes' Newton tolerance)
TEST_MODES_ENERGY_RTOL = 1e-8
#: tiny amplitude (1e-7 fy/kt) vs the linear stuck mode, relative
TEST_MODES_LINEAR_RTOL = 1e-6
#: several harmonics vs one harmonic where the loop is mildly nonlinear (relative)
TEST_MODES_ONE_HARMONIC_RTOL = 1e-2
#: H = 7 vs H = 9 (converged in H; relative, measured in docs/modes.md)
TEST_MODES_H_CONVERGED_RTOL = 2e-3
#: single-mode synthesis vs full harmonic balance: peak amplitude and frequency (relative)
TEST_MODES_SYNTHESIS_RTOL = 2e-2
#: EPMC vs tmdsimpy's EPMC on the Jenkins damper at the default discretisation:
#: frequency and damping ratio (relative; the issue's thresholds)
TEST_MODES_TMDSIMPY_OMEGA_RTOL = 1e-3
TEST_MODES_TMDSIMPY_DAMPING_RTOL = 1e-2
#: ... and with tmdsimpy's own discretisation (H = 7, 4096 samples): the same
#: discrete equations, equal to rounding (measured 1e-12)
TEST_MODES_TMDSIMPY_SAME_RTOL = 1e-9
#: EPMC on a Craig-Bampton reduction with every interior mode kept vs the full
#: model's EPMC (60-DOF chain, 2 Iwan contacts): frequency, damping ratio and
#: mode shape (relative; measured below 1e-8, the Newton tolerance's floor)
TEST_MODES_CB_FULL_RTOL = 1e-6
#: ... with 20 of 57 fixed-interface modes (relative; measured 3e-5 in
#: frequency, 6e-5 in damping ratio)
TEST_MODES_CB_20_MODES_RTOL = 2e-4
#: QSMA of the uniform Iwan contact vs the closed-form Masing secant and loop
#: area (the Hermite-corrected work integral is exact for the quadratic backbone)
TEST_QSMA_MASING_RTOL = 1e-9
#: harmonic-balance branches: largest distance between the straight line
#: joining two reported points and the curve, in the plane (gamma, ln q)
#: (0.01: 1 % of the amplitude; issue 9)
TEST_HB_CHORD_TOL = 1e-2
#: a peak of an automatically discretised HB branch vs harmonic balance solved afresh at its gamma with both
#: more harmonics and more samples (relative to the highest peak): each refinement alone changes it by at most
#: config.HB_AUTO_RTOL (checked by the branch), both together and the fixed gamma add to it
TEST_HB_AUTO_CONVERGED_RTOL = 3e-3
