"""
Identify a joint from a measured backbone
=========================================

Ring-down or stepped-sine tests give, for one mode, the natural frequency
and the damping ratio against the vibration amplitude. ``jd.fit_backbone``
fits a modal Iwan model to them: a linear stiffness k, a joint law (here the
uniform Iwan law: kt and fy) and a linear damping ratio zeta, with the
frequency and damping of each amplitude from the one-harmonic describing
function. The "measurement" is a backbone computed by EPMC (the nonlinear
mode) of a known oscillator, so the answer is known.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import jointdyn as jd
from jointdyn.modes import epmc

# %%
# The oscillator: m = 2 kg, k = 4e5 N/m, an Iwan joint with kt = 1e5 N/m and
# fy = 10 N, and a modal dashpot with zeta = 0.2 % at the stuck frequency.

m, k, zeta = 2.0, 4e5, 0.002
law = jd.make_law("iwan", kt=1e5, mu=0.1, n_ref=100.0)
system = jd.System.sdof(m=m, k=k, law=law, c=2 * zeta * math.sqrt((k + law.kt) * m))
b = epmc(system, (0.03 * law.x_slip, 30 * law.x_slip), harmonics=1, samples=1024, progress=False)
print(f"{b.points} backbone points from {b.amplitude_m[0]:.3g} to {b.amplitude_m[-1]:.3g} m")

# %%
# The fit (the modal mass is known from the test set-up or a model).

fit = jd.fit_backbone(b.amplitude_m, b.omega_rad_s, b.damping_ratio, mass=m, model="iwan")
print(fit.status.value)
for name, value in (("k", k), ("kt", law.kt), ("fy_N", law.fy), ("zeta", zeta)):
    print(f"{name:5s} {fit.parameters[name]:.6g} +- {fit.standard_errors[name]:.2g}   (true {value:g})")

# %%
# Measured and fitted frequency and damping against amplitude.

fig, (a1, a2) = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True, layout="constrained")
a1.semilogx(b.amplitude_m, b.omega_rad_s, "o", ms=3, color="0.5", label="measured (EPMC)")
a1.semilogx(b.amplitude_m, fit.fitted["omega_rad_s"], color="C0", label="fitted")
a1.set_ylabel("omega (rad/s)")
a1.legend()
a1.grid(alpha=0.3)
a2.semilogx(b.amplitude_m, b.damping_ratio, "o", ms=3, color="0.5")
a2.semilogx(b.amplitude_m, fit.fitted["damping_ratio"], color="C1")
a2.set_xlabel("modal amplitude (m)")
a2.set_ylabel("damping ratio")
a2.grid(alpha=0.3)
plt.show()
