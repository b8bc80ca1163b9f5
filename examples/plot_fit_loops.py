"""
Identify a joint from measured loops
====================================

A fretting rig records the tangential displacement ``x``, the normal load
``N`` and the tangential force ``T`` of a joint against time. Here the
"measurement" is synthetic, so that the answer is known: Segalman's
four-parameter Iwan law (kt = 1e5 N/m, mu = 0.1, chi = -0.6, beta = 0.3),
loops of growing amplitude under a normal load varying by 50 %, and 1 % noise
on the force. ``jd.fit_loops`` fits the law's force under the measured x and
N to T and reports every parameter with its standard error.
"""

import matplotlib.pyplot as plt
import numpy as np

import jointdyn as jd

# %%
# The record: four cycles growing from 5 % to 150 % of the macroslip
# displacement, N = 100 N (1 + 0.5 sin(2 pi t + 0.9)).

true = jd.make_law("segalman", kt=1e5, mu=0.1, n_ref=100.0, chi=-0.6, beta=0.3)
t = np.linspace(0.0, 4.0, 8001)
x = true.x_slip * np.sin(2 * np.pi * t) * np.interp(t, [0.0, 4.0], [0.05, 1.5])
N = 100.0 * (1.0 + 0.5 * np.sin(2 * np.pi * t + 0.9))
T_exact = jd.march(true, x, N)[0]
T = T_exact + 0.01 * np.abs(T_exact).max() * np.random.default_rng(0).normal(size=t.size)

# %%
# The fit. The start values come from the data (initial slope, macroslip
# plateau, energy against amplitude); ``n_ref`` only sets fy_N = mu n_ref.

fit = jd.fit_loops(x, N, T, "segalman", t=t, n_ref=100.0)
print(fit.status.value, "-", fit.message)
for name in ("kt", "mu", "chi", "beta"):
    print(f"{name:5s} {fit.parameters[name]:.5g} +- {fit.standard_errors[name]:.2g}"
          f"   (true {getattr(true, name):g})")
print(f"rms residual {fit.rms_residual:.3g} N (the noise: {0.01 * np.abs(T_exact).max():.3g} N)")

# %%
# Measured and fitted loops, and the residual.

fig, (ax, ar) = plt.subplots(2, 1, figsize=(6.4, 6.0), height_ratios=(3, 1), layout="constrained")
ax.plot(x * 1e3, T, ".", ms=1.5, color="0.6", label="measured")
ax.plot(x * 1e3, fit.fitted["T"], color="C0", lw=1.0, label="fitted segalman")
ax.set_xlabel("x (mm)")
ax.set_ylabel("T (N)")
ax.legend()
ax.grid(alpha=0.3)
ar.plot(t, fit.fitted["T"] - T, color="C3", lw=0.5)
ar.set_xlabel("t (s)")
ar.set_ylabel("residual (N)")
ar.grid(alpha=0.3)
plt.show()
