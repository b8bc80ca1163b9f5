"""A new contact law is one module dropped into ``jointdyn/laws``.

The package is copied to a temporary directory, a small law module is
written into the copy's ``laws/`` (nothing else is edited), and the copy is
run through the command line: ``jointdyn loop`` (energy per cycle against the
law's closed form), ``jointdyn frc --method time`` and ``--method hb`` on tiny
gamma grids. The law: a spring kt in series with a slider whose limit is
``ratio * mu * N`` (``ratio`` its own parameter, declared with ``law_param``).
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import jointdyn

SLIDER = textwrap.dedent(
    '''
    """Spring kt in series with a slider of limit ratio * mu * N (a plug-in law)."""

    from dataclasses import dataclass
    from typing import ClassVar

    import numpy as np

    from .._jit import jit
    from ._base import MACROSLIP, SEPARATION, STICK_SLIP, ContactLaw, law_param, register

    # params [kt, fy, n_ref, ratio]; state [x_prev, p]


    @jit
    def slider_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
        kt, fy, n_ref, ratio = params[0], params[1], params[2], params[3]
        s_new[0] = x
        for j in range(dx.shape[0]):
            ds_new[0, j] = dx[j]
        if N <= 0.0:
            s_new[1] = 0.0
            for j in range(dx.shape[0]):
                ds_new[1, j] = 0.0
                dT[j] = 0.0
            return 0.0, 0.0, SEPARATION
        lim = ratio * fy * (N / n_ref)
        p = s_old[1] + kt * (x - s_old[0])
        if p > lim or p < -lim:
            sg = 1.0 if p > 0.0 else -1.0
            s_new[1] = sg * lim
            for j in range(dx.shape[0]):
                ds_new[1, j] = sg * ratio * fy * dN[j] / n_ref
                dT[j] = ds_new[1, j]
            return sg * lim, 0.0, MACROSLIP
        s_new[1] = p
        for j in range(dx.shape[0]):
            ds_new[1, j] = ds_old[1, j] + kt * (dx[j] - ds_old[0, j])
            dT[j] = ds_new[1, j]
        return p, kt, STICK_SLIP


    @jit
    def slider_step(params, s_old, s_new, x, N):
        kt, fy, n_ref, ratio = params[0], params[1], params[2], params[3]
        s_new[0] = x
        if N <= 0.0:
            s_new[1] = 0.0
            return 0.0, 0.0, SEPARATION
        lim = ratio * fy * (N / n_ref)
        p = s_old[1] + kt * (x - s_old[0])
        if p > lim or p < -lim:
            sg = 1.0 if p > 0.0 else -1.0
            s_new[1] = sg * lim
            return sg * lim, 0.0, MACROSLIP
        s_new[1] = p
        return p, kt, STICK_SLIP


    @jit
    def slider_init(params, x0, n0, s):
        s[0] = x0
        s[1] = 0.0


    @jit
    def slider_init_jvp(params, x0, dx0, n0, dn0, s, ds):
        slider_init(params, x0, n0, s)
        for j in range(dx0.shape[0]):
            ds[0, j] = dx0[j]
            ds[1, j] = 0.0


    @dataclass(frozen=True)
    class Slider(ContactLaw):
        """Spring kt in series with a slider of limit ratio mu N."""

        ratio: float = law_param(1.0, low=0.0, high=10.0, help="slider limit over mu N")
        name: ClassVar[str] = "slider"

        step = property(lambda self: slider_step)
        step_jvp = property(lambda self: slider_step_jvp)
        init = property(lambda self: slider_init)
        init_jvp = property(lambda self: slider_init_jvp)
        params = property(lambda self: np.array([self.kt, self.fy, self.n_ref, self.ratio]))
        state_size = property(lambda self: 2)
        x_slip = property(lambda self: self.ratio * self.fy / self.kt)

        def max_force(self, N):
            return self.ratio * super().max_force(N)


    register("slider", Slider)
    '''
)


def _run(env, cwd, *args):
    return subprocess.run([sys.executable, "-m", "jointdyn", *args], env=env, cwd=cwd,
                          capture_output=True, text=True)


def test_law_module_dropped_into_a_copy_runs_through_the_cli(tmp_path):
    src = Path(jointdyn.__file__).resolve().parent
    copy = tmp_path / "src" / "jointdyn"
    # compiled caches travel along (copy2 keeps the stamps Numba checks), so
    # only the loops bound to the new law compile
    shutil.copytree(src, copy)
    (copy / "laws" / "slider.py").write_text(SLIDER)
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "src"))

    # loop: the energy of a steady cycle of an elastic-perfectly-plastic
    # element, 4 Fs (A - Fs / kt), Fs = ratio mu N
    kt, mu, n_ref, ratio, amp = 1e5, 0.1, 100.0, 0.5, 5e-4
    r = _run(env, tmp_path, "loop", "--model", "slider", "--law-param", f"ratio={ratio}", "--kt", str(kt),
             "--mu", str(mu), "--n-ref", str(n_ref), "--amplitude", str(amp), "--json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    fs = ratio * mu * n_ref
    assert d["model"] == "slider" and d["parameters"]["ratio"] == ratio
    assert d["energy_J"] == pytest.approx(4 * fs * (amp - fs / kt), rel=1e-3)
    assert d["force_max_N"] == pytest.approx(fs, rel=1e-12)
    assert "slider" in _run(env, tmp_path, "loop", "--help").stdout

    # its parameter is validated like any other (one line, exit 2)
    for bad in (("--law-param", "ratio=20"), ("--law-param", "n=3"), ("--n", "3")):
        r = _run(env, tmp_path, "loop", "--model", "slider", *bad, "--json")
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr

    # frc, time domain and harmonic balance, on tiny grids
    common = ("frc", "--model", "slider", "--law-param", "ratio=0.8", "--eta", "0.3", "--beta", "2",
              "--gamma", "1.2:1.3:0.1", "--json")
    r = _run(env, tmp_path, *common, "--method", "time", "--sweep", "up", "--workers", "1")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    up = d["directions"]["up"]
    assert d["law_params"] == {"ratio": 0.8}
    assert up["gamma"] == [1.2, 1.3] and up["status"] == ["periodic", "periodic"]
    amp_time = np.array(up["amplitude_m"], float)
    assert np.all(np.isfinite(amp_time) & (amp_time > 0))

    r = _run(env, tmp_path, *common, "--method", "hb", "--harmonics", "3", "--samples", "32")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["status"] == "complete"
    g = np.array([v for b in d["branches"] for v in b["gamma"]], float)
    a = np.array([v for b in d["branches"] for v in b["amplitude_m"]], float)
    assert g.min() == pytest.approx(1.2) and g.max() == pytest.approx(1.3)
    assert np.all(np.isfinite(a) & (a > 0))
    # harmonic balance (3 harmonics) and the time-domain steady state agree
    order = np.argsort(g)
    assert np.interp([1.2, 1.3], g[order], a[order]) == pytest.approx(amp_time, rel=0.02)
