"""
A harmonic-balance branch and its stability
===========================================

With separation (eta = 1.5) and the paper's closed-form rule (chosen on
purpose: ``model="iwan-paper"``), the response curve of the damper bends
over: between two folds a stretch of the branch is unstable, and a sweep in
the time domain jumps over it. Harmonic balance follows the whole branch by
arc-length continuation and tells the stable and unstable parts apart
(Hill's method); up and down sweeps in the time domain land on the stable
parts. The default contact law, the exact Iwan model, has no fold here: the
bend is the closed form's.
"""

import matplotlib.pyplot as plt
import numpy as np

import jointdyn as jd

system = jd.System.paper_damper(eta=1.5, beta=2.0, model="iwan-paper")
branch = jd.frc_hb(system, 0.9, 1.4, samples=512, progress=False)
folds = branch.gamma.values[branch.fold.values.astype(bool)]
print(branch.attrs["status"], f"{branch.sizes['point']} points, folds at gamma =", np.round(folds, 4))
exact = jd.frc_hb(jd.System.paper_damper(eta=1.5, beta=2.0), 0.9, 1.4, samples=512, progress=False)
print("exact Iwan model (default):", exact.attrs["status"], int(exact.fold.sum()), "folds")

# %%
# Time-domain sweeps up and down on a coarse grid, for comparison.

gammas = np.round(np.arange(0.9, 1.4001, 0.02), 10)
sweep = jd.frc_sweep(gammas, etas=(1.5,), betas=(2.0,), model="iwan-paper", progress=False)

fig, ax = plt.subplots(figsize=(6.8, 4.6), layout="constrained")
g = branch.gamma.values
a = branch.amplitude_q.values
stable = branch.stable.values.astype(bool)
ax.plot(g, np.where(stable, a, np.nan), "-", color="C0", label="HB stable")
ax.plot(g, np.where(~stable, a, np.nan), "--", color="C3", label="HB unstable")
ax.plot(g[branch.fold.values.astype(bool)], a[branch.fold.values.astype(bool)], "ks", mfc="none", label="fold")
ax.plot(exact.gamma, exact.amplitude_q, "-", color="0.6", lw=1, label="HB, exact Iwan model (default)")
for direction, marker in (("up", "^"), ("down", "v")):
    line = sweep.amplitude_q.sel(eta=1.5, beta=2.0, delta=0.0, direction=direction)
    ax.plot(gammas, line, marker, color="0.3", mfc="none", ms=5, label=f"time domain, sweep {direction}")
ax.set_xlabel("gamma = w / w0")
ax.set_ylabel("half peak-to-peak amplitude of q")
ax.set_title("eta = 1.5, beta = 2, the paper's closed-form rule (iwan-paper)")
ax.grid(alpha=0.3)
ax.legend(fontsize=8)

plt.show()
