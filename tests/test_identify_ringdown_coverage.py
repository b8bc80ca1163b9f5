"""A ring-down through macroslip over 20 noise seeds (the must-hold of the identification
work: within 0.5 % in frequency and 5 % in damping ratio of the EPMC backbone over the
amplitudes the decay covers, parameters within 3 % where determined, and the true value inside
the reported 95 % interval, or the parameter named not determined, in at least 90 % of the fits
for every parameter).

The Iwan SDOF of tests/test_identify_ringdown.py (m = 2 kg, k = 4e5 N/m, kt = 1e5 N/m,
fy = 20 N, zeta = 0.2 %) released from 5 slip displacements, 150 periods at 64 samples per
period: one time integration, white noise of 1 % of its peak added per seed (seeds 0 to 19),
as benchmarks/coverage_ringdown.py macroslip does (which also runs seeds 20 to 39). "The
amplitudes the decay covers" are those of the fit's ``damping_range``: where the windows'
measured noise fixes the fitted damping ratio within +-5 % (95 %): from the top window (1.97 to
1.99 slip displacements) down to 0.27 to 0.48. Over all windows, down to the noise, four of these
seeds missed 5 % (5.9 to 10.3 %); over the range the largest miss was 4.4 %. About 12 s of CPU
time per seed."""

from __future__ import annotations

import math

import numpy as np

from test_identify_ringdown import _decay, _sdof

SEEDS = 20
TRUE = {"k": 4e5, "kt": 1e5, "fy_N": 20.0, "zeta": 0.002}


def test_ringdown_through_macroslip_over_20_noise_seeds():
    from jointdyn.identify import backbone_from_ringdown, fit_ringdown
    from jointdyn.modes import epmc

    system, law = _sdof("iwan")
    t, x0 = _decay(system, law, [5.0 * law.x_slip], 0, math.sqrt(5e5 / 2.0), 150, 64, noise=0.0)
    bb = epmc(system, (0.05 * law.x_slip, 3.0 * law.x_slip), harmonics=3, progress=False)
    assert bb.status.ok, bb.message
    la = np.log(bb.amplitude_m)
    held = {k: 0 for k in TRUE}
    for seed in range(SEEDS):
        x = x0 + 0.01 * np.max(np.abs(x0)) * np.random.default_rng(seed).normal(size=x0.size)
        b = backbone_from_ringdown(t, x, "x", band=(300.0, 750.0))
        fit = fit_ringdown(b, mass=2.0, model="iwan")
        at = np.log(b.amplitude_m)
        assert b.amplitude_m.min() > 0.05 * law.x_slip and b.amplitude_m.max() < 3.0 * law.x_slip
        ew = fit.fitted["omega_rad_s"] / np.interp(at, la, bb.omega_rad_s) - 1.0
        assert np.max(np.abs(ew)) < 0.005, (seed, ew)
        inside = np.array(fit.damping_range["determined"], bool)
        assert inside.any(), (seed, fit.message)
        eD = fit.fitted["damping_ratio"] / np.interp(at, la, bb.damping_ratio) - 1.0
        assert np.max(np.abs(eD[inside])) < 0.05, (seed, eD, inside)
        for k, v in TRUE.items():
            covers = fit.intervals[k].covers(v)
            if fit.parameters[k] is None:
                assert k in fit.not_identifiable
                held[k] += 1
            else:
                assert abs(fit.parameters[k] / v - 1.0) < 0.03, (seed, k, fit.parameters[k])
                held[k] += covers
    assert all(h >= 0.9 * SEEDS for h in held.values()), held
