"""
Loops from a measured history
=============================

A test rig records the tangential displacement ``x`` (m) and the normal load
``N`` (N) of a joint against time ``t`` (s). jointdyn reads such a CSV file,
marches the exact Iwan contact through it and measures every cycle.

The file ``data/history.csv`` shipped with the examples is a *synthetic*
record in that format: three cycles of a 2 Hz motion of 0.3 mm with a slow
drift, a normal load of 120 N varying by 120 % (so the joint opens once per
cycle), and a little noise on both channels.
"""

from pathlib import Path

import matplotlib.pyplot as plt

import jointdyn as jd

# %%
# Read the history (columns ``t, x, N`` in SI units; other columns are
# ignored) and choose the contact: the exact Iwan model (the default law,
# every slip force following N(t)), with the preload as reference load.

here = Path(__file__).parent if "__file__" in globals() else Path.cwd()
t, x, N = jd.read_history_csv(here / "data" / "history.csv")
law = jd.Iwan(kt=2e5, mu=0.3, n_ref=120.0)
print(f"{t.size} samples over {t[-1] - t[0]:.2f} s; N from {N.min():.0f} to {N.max():.0f} N")

# %%
# March the law and cut the history into cycles of the forcing period. Where
# N changes sign between two samples, the exact opening or closing instant is
# inserted, so the result has a few more samples than the file.

r = jd.quasistatic(law, t, x, N, period=0.5)
print(f"{r.t.size - t.size} separation/re-contact instants inserted")
print(r.cycles[["cycle", "energy_J", "stick_slip_fraction", "macroslip_fraction",
                "separation_fraction"]].round(5).to_string(index=False))

# %%
# The loops, coloured by motion state.

fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
colors = {"stick-slip": "C0", "macroslip": "C3", "separation": "0.6"}
for name, color in colors.items():
    sel = r.state == name
    ax.plot(r.x[sel] * 1e3, r.T[sel], ".", ms=2.5, color=color, label=name)
ax.plot(r.x * 1e3, r.T, color="k", lw=0.4, alpha=0.5)
ax.set_xlabel("tangential displacement x (mm)")
ax.set_ylabel("tangential force T (N)")
ax.set_title("Measured history through the exact Iwan model")
ax.legend(markerscale=4)
ax.grid(alpha=0.3)

plt.show()
