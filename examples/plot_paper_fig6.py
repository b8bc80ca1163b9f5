"""
The paper's Fig 6 in a few lines
================================

Steady response of the paper's friction damper against the frequency ratio
gamma, swept up and down, for two normal-load ratios eta (in contact and with
separation) and two forcing levels beta. The full figure (4 x 6 curves) is
``jointdyn figures --only fig6``; this is a small grid of it, with the
default contact law (``ds.attrs["model"]``: the exact Iwan model).
"""

import matplotlib.pyplot as plt
import numpy as np

import jointdyn as jd
from jointdyn.sweeps import to_frame

gammas = np.round(np.arange(0.8, 1.6001, 0.02), 10)
ds = jd.frc_sweep(gammas, etas=(0.5, 1.5), betas=(2.0, 10.0), directions=("up", "down"), progress=False)
df = to_frame(ds)
print(df.groupby(["eta", "beta"]).status_name.value_counts().unstack(fill_value=0))

# %%
# Only periodic points carry an amplitude (NaN otherwise), so a point
# without a steady state is never drawn as a number.

fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True, layout="constrained")
for ax, (eta, sub) in zip(axes, df.groupby("eta")):
    for k, (beta, line) in enumerate(sub.groupby("beta")):
        for direction, style in (("up", "-"), ("down", "--")):
            d = line[line.direction == direction]
            ax.plot(d.gamma, d.amplitude_q, style, color=f"C{k}",
                    label=f"beta = {beta:g}, sweep {direction}")
    ax.set_yscale("log")
    ax.set_title(f"eta = {eta:g}, contact model {ds.attrs['model']}")
    ax.set_xlabel("gamma = w / w0")
    ax.grid(alpha=0.3, which="both")
axes[0].set_ylabel("half peak-to-peak amplitude of q = kt x / fy")
axes[1].legend(fontsize=8)

plt.show()
