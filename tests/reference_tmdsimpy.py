"""Reference numbers of an established tool for the nonlinear-mode tests: tmdsimpy's EPMC.

Provenance
----------
Tool: tmdsimpy (Tribomechadynamics Simulations for Python, github.com/tmd-lab/tmdsimpy),
commit 17d5fc3ffa22c8ac6f38e5b77e3a396aae261e7b (2025-02-07), run with numpy 2.4.6 and
scipy 1.17.1 in a scratch virtual environment outside this repository (its code is not
part of jointdyn).

Script (summary): ``VibrationSystem(M=[[10]], K=[[3.9e5]], ab=[0, 0])`` with one
``VectorJenkins(Q=[[1]], T=[[1]], kt=3e5, Fs=50)`` (the paper's damper with a single
Jenkins element: m = 10 kg, k = 3.9e5 N/m, kt = 3e5 N/m, slip force 50 N, no viscous
damping); harmonics h = 0..7; ``epmc_res(..., Nt=4096, aft_tol=1e-12)`` with the
phase constraint "sine coefficient of harmonic 1 = 0"; solved by tmdsimpy's
``NonlinearSolver.nsolve`` (scipy ``root``, hybr, xtol 1e-13) at 400 log-spaced
amplitudes from 0.5 to 100 fy/kt, each from the previous solution, starting from the
linear stuck mode. tmdsimpy's modal amplitude multiplies a mass-normalised first
harmonic, so the first-harmonic amplitude of x is ``10**la * hypot(a1, b1)``. Recorded
at the amplitudes below: the first-harmonic amplitude (m), the frequency (rad/s) and
the damping ratio xi / (2 omega). Residuals were below 4e-13 N at every point.

Checked again on 2026-12-01 by a second, independent run of the same tmdsimpy
commit (same numpy and scipy; ``scipy.optimize.root``, hybr, with tmdsimpy's
Jacobian, 400 log-spaced steps from the stuck mode, then a solve at exactly the
recorded amplitude) at 8.33e-5, 1.75e-4, 5e-4 and 1.67e-2 m: the frequencies
equal the recorded ones to every digit and the damping ratios to 2e-15
(relative).
"""

#: harmonics and AFT time samples per period of the reference run
HARMONICS = 7
SAMPLES = 4096

#: (first-harmonic amplitude m, natural frequency rad/s, damping ratio)
TMDSIMPY_JENKINS_EPMC = (
    (8.333333333333336e-05, 262.67851073127395, 1.280489904930271e-17),
    (0.000175, 261.70428990531957, 0.012373229113580197),
    (0.00020000000000000004, 256.4760374735879, 0.03951552691995695),
    (0.00024999999999999995, 245.67383597512585, 0.06958043862644714),
    (0.0003333333333333332, 232.53811076719848, 0.08820892785704308),
    (0.0004999999999999999, 218.5160897075236, 0.08936304124363764),
    (0.0008333333333333337, 207.9185788425229, 0.07114484807415974),
    (0.0016666666666666676, 201.32682078575994, 0.042585661244738914),
    (0.005000000000000002, 198.24473676704372, 0.015677569996875723),
    (0.016666666666666666, 197.61106281389894, 0.004842990325536656),
)
