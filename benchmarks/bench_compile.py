"""Cold compile of the whole package: the compiled code a user's first runs need.

One fresh process per side with its own empty ``NUMBA_CACHE_DIR`` runs the
commands a new user runs first, with the default contact law and with the
discrete Iwan law (the law whose kernels are unchanged across versions, for
comparisons between versions): a quasi-static loop, a time-domain response
curve on a short grid, a harmonic-balance branch with stability. The same
commands are then run again in a fresh process that loads the compiled code
from that cache (the reference: everything but the compilation).

First, each of the README's first commands alone (``readme_hb``: ``jointdyn frc
--method hb --eta 0.5 --beta 2 --json``; ``readme_loop``: ``jointdyn loop --eta 1.2
--delta 90 --json``), cold then warm in fresh processes, beside their targets
(issue 33: cold <= 5 s and <= 3 s on a quiet machine).

Reported, seconds of wall time of the whole process (imports included):

* ``cold_seconds``: the empty cache (compiles everything the commands use);
* ``warm_seconds``: the same commands loading the cache;
* ``compile_seconds``: their difference, the cost of compilation.

The cold and warm runs alternate over the rounds (best of rounds each);
``--quick`` runs one round of the README's commands only.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_SCRIPT = r"""
import sys, tempfile, time
from jointdyn.cli import main
t0 = time.perf_counter()
models = sys.argv[1].split(",")
with tempfile.TemporaryDirectory() as d:
    for model in models:
        extra = ["--n", "50"] if model == "discrete" else []
        for args in (["loop", "--model", model, *extra, "--out", f"{d}/loop-{model}"],
                     ["frc", "--model", model, *extra, "--gamma", "0.9:1.1:0.1", "--json"],
                     ["frc", "--method", "hb", "--model", model, *extra, "--eta", "0.5", "--beta", "2",
                      "--gamma", "0.8:1.2:0.01", "--json"]):
            try:
                main(args)
            except SystemExit as exc:
                if exc.code not in (0, None):
                    raise
"""


def _env(cache: str) -> dict:
    """Environment of a fresh process running this tree's jointdyn with the kernel cache under ``cache``."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src")] + [p for p in [env.get("PYTHONPATH")] if p])
    env["NUMBA_CACHE_DIR"] = cache
    env.pop("JOINTDYN_CACHE_DIR", None)
    env["MPLBACKEND"] = "Agg"
    return env


def _one(models: str, cache: str) -> float:
    env = _env(cache)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", _SCRIPT, models], env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


#: the README's first commands and the cold time each should take (s, quiet machine)
README_COMMANDS = {
    "readme_hb": (["frc", "--method", "hb", "--eta", "0.5", "--beta", "2", "--json"], 5.0),
    "readme_loop": (["loop", "--eta", "1.2", "--delta", "90", "--json"], 3.0),
}


def _command(args: list, cache: str) -> float:
    """Wall time of ``jointdyn ARGS`` in a fresh process with the Numba cache ``cache``."""
    env = _env(cache)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "jointdyn", *args], env=env, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def _load() -> float:
    try:
        return float(Path("/proc/loadavg").read_text().split()[0])
    except (OSError, ValueError, IndexError):
        return float("nan")


def run(quick: bool) -> dict:
    """Cold and warm whole-process times of a user's first commands (see module docstring)."""
    from jointdyn import config

    rounds = 1 if quick else 2
    out = {}
    for label, (args, target) in README_COMMANDS.items():
        cold, warm = [], []
        load = [_load()]
        for _ in range(rounds):
            with tempfile.TemporaryDirectory(prefix="jointdyn-numba-") as cache:
                cold.append(_command(args, cache))
                warm.append(_command(args, cache))
        load.append(_load())
        out[label] = {"command": "jointdyn " + " ".join(args), "cold_seconds": min(cold),
                      "warm_seconds": min(warm), "cold_target": target, "load_average": load}
    if quick:
        return out
    out["commands"] = "loop, frc (time, 3 points), frc --method hb with stability, per model"
    cases = (("default_model", config.MODEL), ("discrete", "discrete"))
    for label, models in cases:
        cold, warm = [], []
        for _ in range(rounds):
            with tempfile.TemporaryDirectory(prefix="jointdyn-numba-") as cache:
                cold.append(_one(models, cache))
                warm.append(_one(models, cache))
        out[label] = {"model": models, "cold_seconds": min(cold), "warm_seconds": min(warm),
                      "compile_seconds": min(cold) - min(warm)}
    return out


if __name__ == "__main__":
    print(json.dumps(run(quick="--quick" in sys.argv)))
