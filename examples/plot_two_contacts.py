"""
Your own structure with two contacts
====================================

A two-DOF structure (say a blade and a damper platform, reduced to one DOF
each) with two frictional contacts: DOF 0 rubs against the ground under a
normal load that varies at the forcing frequency, and DOF 1 rubs against
DOF 0 under a constant load. The forcing acts on DOF 1. We compute its
response curve by time integration and by harmonic balance.
"""

import matplotlib.pyplot as plt
import numpy as np

import jointdyn as jd

M = np.diag([2.0, 1.0])                                  # kg
K = np.array([[3.0e5, -1.0e5], [-1.0e5, 1.0e5]])         # N/m
C = 2e-5 * K                                             # N s/m, light stiffness-proportional damping
law = jd.Iwan(kt=5e4, mu=0.3, n_ref=200.0)                # the exact Iwan model (the default law)
contacts = (
    jd.Contact(law=law, dof=0, normal=jd.HarmonicLoad(200.0, 60.0)),  # against the ground, N = 200 + 60 sin(w t)
    jd.Contact(law=law, dof=1, dof2=0, normal=jd.ConstantLoad(150.0)),  # between the two DOFs, constant 150 N
)
system = jd.System(M, C, K, contacts=contacts, force=[0.0, 30.0])
print(f"w0 = {system.w0:.1f} rad/s (lowest mode of M, K without the contacts)")

# %%
# Time integration: one steady state per frequency, each starting from the
# previous one (a sweep up).

gammas = np.round(np.arange(0.7, 1.61, 0.05), 10)
amps, start = [], None
for g in gammas:
    ss = jd.steady_state(system, g, start=start, response_dof=1)
    amps.append(ss.amplitude_m if ss.status == "periodic" else np.nan)
    start = ss
print(f"{np.isfinite(amps).sum()} of {len(gammas)} points periodic")

# %%
# Harmonic balance along the same range, with stability.

branch = jd.frc_hb(system, 0.7, 1.6, response_dof=1, progress=False)
print(branch.attrs["status"], branch.sizes["point"], "points")

fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
stable = branch.stable.values.astype(bool)
ax.plot(branch.gamma, np.where(stable, branch.amplitude_m * 1e6, np.nan), "-", color="C0",
        label="harmonic balance, stable")
ax.plot(branch.gamma, np.where(~stable, branch.amplitude_m * 1e6, np.nan), "--", color="C0",
        label="harmonic balance, unstable")
ax.plot(gammas, np.asarray(amps) * 1e6, "o", color="C1", mfc="none", label="time integration")
ax.set_xlabel("gamma = w / w0")
ax.set_ylabel("half peak-to-peak amplitude of DOF 1 (um)")
ax.set_yscale("log")
ax.grid(alpha=0.3, which="both")
ax.legend()

plt.show()
