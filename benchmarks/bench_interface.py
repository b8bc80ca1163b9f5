"""Interface node pairs (issue 23): cost of a step per pair against the number of pairs.

The compiled march of an interface (``interface_march``: every pair stepped at
every sample, 2-D slip, normal load from g) over a circular orbit with a
varying normal approach (stick, slip and separation all occur), at 16, 256
and 4096 pairs, beside the march of one Jenkins element (the 1-D element of
the contact laws, ``drivers.march``) over the same number of element steps,
the sizes alternating, best of several rounds. Reported: ns per pair-step at
each size, their ratio to the 16-pair figure (target: 256 pairs within 1.2x,
linear cost in the number of pairs) and to the Jenkins element; the same for
the forward-mode kernel (``interface_step_jvp``, 3 directions per pair,
called per sample from a compiled loop).
"""

from __future__ import annotations

import time

import numpy as np

TARGET_RATIO = 1.2


def _orbit(nt, npairs, rng):
    from jointdyn.interfaces import Interface

    t = np.arange(nt) / 256.0
    ph = rng.uniform(0.0, 2 * np.pi, npairs)
    a = rng.uniform(0.5e-3, 2e-3, npairs)
    U = np.empty((nt, npairs, 2))
    U[:, :, 0] = a * np.cos(2 * np.pi * t[:, None] + ph)
    U[:, :, 1] = a * np.sin(2 * np.pi * t[:, None] + ph)
    G = np.ascontiguousarray(1.5e-3 * np.sin(2 * np.pi * t[:, None] + 2 * ph))
    it = Interface(kt=1e3, kn=1e3, mu=0.5, preload=rng.uniform(0.5, 2.0, npairs),
                   pairs=np.arange(6 * npairs).reshape(npairs, 6))
    return it, U, G


def _jvp_loop_template(params, w0, U, dU, G, dG, T, dT, N, dN, code):  # pragma: no cover - compiled
    a = w0.copy()
    b = w0.copy()
    da = np.zeros(dU.shape[1:])
    db = np.zeros(dU.shape[1:])
    for j in range(U.shape[0]):
        k = j - 1 if j > 0 else 0
        JVP(params, U[k], dU[k], G[k], dG[k], U[j], dU[j], G[j], dG[j], a, da, b, db, T, dT, N, dN, code)  # noqa: F821
        a, b = b, a
        da, db = db, da


def run(quick: bool) -> dict:
    from jointdyn import Jenkins
    from jointdyn._jit import specialize
    from jointdyn.drivers._march import _march_unchecked
    from jointdyn.interfaces import interface_march, interface_step_jvp

    rng = np.random.default_rng(0)
    work = 2**17 if quick else 2**20  # pair-steps per measurement
    rounds = 3 if quick else 5
    sizes = (16, 256, 4096)
    cases = {n: _orbit(max(work // n, 64), n, rng) for n in sizes}
    jvp = specialize(_jvp_loop_template, JVP=interface_step_jvp)
    jen = Jenkins(kt=1e3, mu=0.5, n_ref=1.0)
    xj = 2e-3 * np.sin(2 * np.pi * np.arange(work) / 256.0)
    Nj = 1.0 + 0.8 * np.sin(4 * np.pi * np.arange(work) / 256.0)
    s0 = jen.initial_state(0.0, 1.0)

    def step(n):
        it, U, G = cases[n]
        nt = G.shape[0]
        T, N = np.empty((nt, n, 2)), np.empty((nt, n))
        code = np.empty((nt, n), dtype=np.int8)
        t0 = time.perf_counter()
        interface_march(it.params, np.ascontiguousarray(U[0]), U, G, T, N, code, np.empty((n, 2)))
        return (time.perf_counter() - t0) / (nt * n) * 1e9, code

    def step_jvp(n):
        it, U, G = cases[n]
        nt = G.shape[0]
        dU = np.zeros((nt, n, 2, 3))
        dU[:, :, 0, 0] = 1.0
        dU[:, :, 1, 1] = 1.0
        dG = np.zeros((nt, n, 3))
        dG[:, :, 2] = 1.0
        T, N, code = np.empty((n, 2)), np.empty(n), np.empty(n, dtype=np.int8)
        dT, dN = np.empty((n, 2, 3)), np.empty((n, 3))
        t0 = time.perf_counter()
        jvp(it.params, np.ascontiguousarray(U[0]), U, dU, G, dG, T, dT, N, dN, code)
        return (time.perf_counter() - t0) / (nt * n) * 1e9

    def jenkins():
        t0 = time.perf_counter()
        _march_unchecked(jen, xj, Nj, s0)
        return (time.perf_counter() - t0) / work * 1e9

    step(16), step_jvp(16), jenkins()  # compile / load the cache
    best = {("step", n): np.inf for n in sizes} | {("jvp", n): np.inf for n in sizes} | {"jenkins": np.inf}
    states = None
    for r in range(rounds):
        order = sizes if r % 2 == 0 else sizes[::-1]
        for n in order:
            ns, code = step(n)
            best[("step", n)] = min(best[("step", n)], ns)
            best[("jvp", n)] = min(best[("jvp", n)], step_jvp(n))
            if n == 256:
                states = np.bincount(code.ravel(), minlength=3) / code.size
        best["jenkins"] = min(best["jenkins"], jenkins())
    out = {"pair_steps_per_measurement": work, "rounds": rounds, "target_ratio": TARGET_RATIO,
           "jenkins_ns_per_step": best["jenkins"],
           "state_fractions_256": {"stick": float(states[0]), "slip": float(states[1]), "open": float(states[2])}}
    for kind in ("step", "jvp"):
        for n in sizes:
            out[f"{kind}_ns_per_pair_{n}"] = best[(kind, n)]
            out[f"{kind}_ratio_{n}_vs_16"] = best[(kind, n)] / best[(kind, 16)]
        out[f"{kind}_ratio_vs_jenkins_256"] = best[(kind, 256)] / best["jenkins"]
    out["within_target"] = bool(out["step_ratio_256_vs_16"] <= TARGET_RATIO and out["jvp_ratio_256_vs_16"] <= TARGET_RATIO)
    return out
