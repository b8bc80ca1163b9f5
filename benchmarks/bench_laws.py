"""Speed of the contact-law kernels (``python benchmarks/run.py --only laws``).

Measured, each beside a reference taken in the same run:

* the exact Iwan law (``iwan``, the default) and the closed-form Iwan law
  (``iwan-closed``: full memory; ``iwan-paper``: the paper's last-reversal
  rule): kernel steps per second over a long steady cycle with macroslip
  (x = 1.5 x_slip sin, 2000 samples per cycle), best of several repeats of
  ``jointdyn.march``;
* discrete Iwan with n = 1000 elements: steps per second (and element steps);
* the ratio of each against a straightforward pure-Python implementation of
  the same law (``tests/reference.py``) on a shorter history;
* JIT compile time: the first ``march`` call (kernel and march loop) and the
  first ``step_jvp`` call in a fresh process with an empty temporary
  ``NUMBA_CACHE_DIR`` (compiles), then the same in a second fresh process that
  loads the compiled code from that cache; Numba's own one-off start-up (the
  first compilation of a trivial function) is measured before and reported
  apart as ``numba_startup_s``.

Targets (issue 2): closed form (and the exact law that replaces it as the
default) >= 3e7 steps/s, discrete n = 1000 >= 1e6 steps/s.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
for _p in (ROOT / "src", ROOT / "tests"):
    if _p.is_dir() and str(_p) not in sys.path:
        sys.path.insert(0, str(_p))

TARGET_CLOSED_FORM = 3e7
TARGET_DISCRETE_1000 = 1e6
KT, MU, NREF = 1e5, 0.1, 100.0


def _history(n_steps, steps_per_cycle=2000, amp_slip=1.5):
    xs = 2.0 * MU * NREF / KT
    t = np.arange(n_steps) / steps_per_cycle
    x = amp_slip * xs * np.sin(2.0 * np.pi * t)
    return x, np.full(n_steps, NREF)


def _best(fn, repeats):
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _compiled_rate(law, n_steps, repeats):
    from jointdyn import march

    x, N = _history(n_steps)
    march(law, x[:8], N[:8])  # compile / load outside the timing
    return n_steps / _best(lambda: march(law, x, N), repeats)


def _python_rate(ref_factory, n_steps, repeats):
    from reference import march_ref

    x, N = _history(n_steps)
    xl, Nl = x.tolist(), N.tolist()
    return n_steps / _best(lambda: march_ref(ref_factory(), xl, Nl), repeats)


_COMPILE_SCRIPT = r"""
import json, sys, time
t0 = time.perf_counter()
import numpy as np
from jointdyn import DiscreteIwan, Iwan, IwanClosedForm, march
t_import = time.perf_counter() - t0
import numba
t0 = time.perf_counter()
numba.njit(lambda v: v + 1.0)(1.0)  # Numba's one-off start-up, not the laws'
out = {"import_s": t_import, "numba_startup_s": time.perf_counter() - t0}
x = np.linspace(0.0, 1e-4, 16); N = np.full(16, 100.0)
for name, law in (("iwan", Iwan(kt=1e5, mu=0.1, n_ref=100.0)),
                  ("iwan_closed", IwanClosedForm(kt=1e5, mu=0.1, n_ref=100.0)),
                  ("discrete", DiscreteIwan(kt=1e5, mu=0.1, n_ref=100.0, n=10))):
    t0 = time.perf_counter(); march(law, x, N); t1 = time.perf_counter()
    march(law, x, N); t2 = time.perf_counter()
    out[name + "_first_call_s"] = (t1 - t0) - (t2 - t1)
    t0 = time.perf_counter()
    law.step_jvp(law.params, law.initial_state(), np.zeros((law.state_size, 1)),
                 np.zeros(law.state_size), np.zeros((law.state_size, 1)),
                 0.0, np.zeros(1), 100.0, np.zeros(1), np.zeros(1))
    out[name + "_jvp_first_call_s"] = time.perf_counter() - t0
print(json.dumps(out))
"""


def _compile_times():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src")] + [p for p in [env.get("PYTHONPATH")] if p])
    with tempfile.TemporaryDirectory(prefix="jointdyn-numba-") as cache:
        env["NUMBA_CACHE_DIR"] = cache
        runs = []
        for _ in range(2):  # cold (compiles into the empty cache), then warm (loads)
            r = subprocess.run(
                [sys.executable, "-c", _COMPILE_SCRIPT], env=env, capture_output=True, text=True, check=True
            )
            runs.append(json.loads(r.stdout.strip().splitlines()[-1]))
    return {"cold_compile": runs[0], "warm_cache_load": runs[1]}


def run(quick: bool) -> dict:
    """Kernel speeds, ratios to pure Python, compile times (see module docstring)."""
    from jointdyn import DiscreteIwan, Iwan, IwanClosedForm
    from reference import DiscreteIwanRef, IwanPaperRef, IwanRef
    from reference_exact import ExactIwanRef

    n_long = 200_000 if quick else 2_000_000
    n_disc = 20_000 if quick else 200_000
    repeats = 3 if quick else 7
    n_py = 20_000 if quick else 100_000
    n_py_disc = 100 if quick else 500

    out = {"history": "x = 1.5 x_slip sin(2 pi t), 2000 samples/cycle, constant N (macroslip every half cycle)"}
    exact = Iwan(kt=KT, mu=MU, n_ref=NREF)
    cases = (
        ("iwan", exact, lambda: ExactIwanRef(KT, MU, NREF, exact.capacity, 0.0, NREF)),
        ("iwan_closed", IwanClosedForm(kt=KT, mu=MU, n_ref=NREF), lambda: IwanRef(KT, MU, NREF, 0.0, NREF)),
        ("iwan_paper", IwanClosedForm(kt=KT, mu=MU, n_ref=NREF, memory="last"),
         lambda: IwanPaperRef(KT, MU, NREF, 0.0, NREF)),
    )
    for label, law, ref in cases:
        rate = _compiled_rate(law, n_long, repeats)
        py = _python_rate(ref, n_py, max(1, repeats // 2))
        out[label] = {
            "steps_per_s": rate,
            "ns_per_step": 1e9 / rate,
            "python_reference_steps_per_s": py,
            "speedup_vs_python": rate / py,
            "target_steps_per_s": TARGET_CLOSED_FORM,
            "target_met": bool(rate >= TARGET_CLOSED_FORM),
            "n_steps": n_long,
        }
    n = 1000
    law = DiscreteIwan(kt=KT, mu=MU, n_ref=NREF, n=n)
    rate = _compiled_rate(law, n_disc, repeats)
    py = _python_rate(lambda: DiscreteIwanRef(KT, MU, NREF, n, 0.0, NREF), n_py_disc, 1)
    out["discrete_n1000"] = {
        "steps_per_s": rate,
        "element_steps_per_s": rate * n,
        "ns_per_element_step": 1e9 / (rate * n),
        "python_reference_steps_per_s": py,
        "speedup_vs_python": rate / py,
        "target_steps_per_s": TARGET_DISCRETE_1000,
        "target_met": bool(rate >= TARGET_DISCRETE_1000),
        "n_steps": n_disc,
    }
    out["jit"] = _compile_times()
    return out


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true")
    print(json.dumps(run(quick=ap.parse_args().quick), indent=2))
