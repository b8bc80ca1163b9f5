"""
A sweep on a Dask cluster
=========================

``frc_sweep`` runs its sweep lines (one eta, beta, delta and direction each)
on any Dask cluster: pass a ``distributed.Client``. Here the cluster is a
small local one; on a real cluster, ``Client("tcp://scheduler:8786")`` (or
``jointdyn frc --scheduler tcp://scheduler:8786``) is the only change. The
result does not depend on where the lines ran.
"""

import matplotlib.pyplot as plt
import numpy as np
from distributed import Client, LocalCluster

import jointdyn as jd

gammas = np.round(np.arange(0.9, 1.5001, 0.02), 10)
with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as cluster:
    with Client(cluster) as client:
        ds = jd.frc_sweep(gammas, etas=(0.5,), betas=(1.0, 2.0, 5.0), directions=("up",), client=client,
                          progress=False)
print(ds)

# %%
# The same sweep in this process gives the same numbers.

serial = jd.frc_sweep(gammas, etas=(0.5,), betas=(1.0, 2.0, 5.0), directions=("up",), n_workers=1,
                      progress=False)
print("identical to the serial run:", bool(serial.amplitude_q.equals(ds.amplitude_q)))

fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
for beta in ds.beta.values:
    ax.plot(gammas, ds.amplitude_q.sel(eta=0.5, beta=beta, delta=0.0, direction="up"), label=f"beta = {beta:g}")
ax.set_xlabel("gamma = w / w0")
ax.set_ylabel("half peak-to-peak amplitude of q")
ax.set_yscale("log")
ax.grid(alpha=0.3, which="both")
ax.legend()

plt.show()
