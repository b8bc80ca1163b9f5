"""What a short command costs before it computes: the modules a process imports.

A command run a second time finds its compiled kernels in Numba's disk
cache. Loading them must not install Numba's compiler (its typing and
lowering registries: :class:`jointdyn._jit._LoadingCache`), and a harmonic-balance
command must not import the libraries only files, plots, progress bars and
distributed sweeps need (xarray, pandas, matplotlib, Dask, tqdm), nor
scipy.linalg. The
modules a process imported are read from ``python -X importtime`` (every
import, one line each), so the tests hold with a cold cache too: the first
run compiles, the second loads.
"""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")
#: a hang guard for subprocesses (the first run may compile), not a speed requirement
HANG_GUARD_S = 900

#: modules that only Numba's registry refresh imports (``CPUContext.load_additional_registries``): a
#: process that imported one of them installed the compiler
COMPILER_ONLY = ("numba.misc.cffiimpl", "numba.np.polynomial.polynomial_functions", "numba.typed.dictimpl")

#: libraries that an hb command without --out does not need; scipy.linalg (0.2-0.4 s) comes in with
#: Numba's BLAS binding, which code loaded from the cache imports when a kernel calls np.dot, @ or
#: numpy's array functions implemented in numba.np.arraymath (np.argmax, np.sum, ...)
NOT_FOR_HB_JSON = ("xarray", "pandas", "matplotlib", "dask", "distributed", "tqdm", "scipy.linalg")

#: Numba's array implementation, whose compiled helpers every kernel that makes an array contains: a
#: cached kernel's environments are rebuilt without importing their modules
#: (:func:`jointdyn._jit._rebuild_env_unimported`), which nopython code never reads
ENVIRONMENT_ONLY = ("numba.np.arrayobj",)

#: the hb command of tests/test_cli_frc.py (its kernels are compiled there in the same cache)
HB_ARGS = ("frc", "--method", "hb", "--gamma", "1.1:1.3:0.1", "--eta", "0.5", "--beta", "2", "--json")


def _env():
    return {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _run(args):
    """(stdout, names of the modules imported) of ``python -X importtime ARGS``."""
    r = subprocess.run([sys.executable, "-X", "importtime", *args], env=_env(), capture_output=True, text=True,
                       timeout=HANG_GUARD_S)
    assert r.returncode == 0, r.stderr[-2000:]
    names = {line.split("|")[-1].strip() for line in r.stderr.splitlines() if line.startswith("import time:")}
    return r.stdout, names


def _imported(names, prefixes):
    return sorted(n for n in names if any(n == p or n.startswith(p + ".") for p in prefixes))


def test_cached_kernel_loads_without_the_compiler():
    """A kernel loaded from the cache gives the compiled result and leaves Numba's compiler out."""
    script = textwrap.dedent(
        """
        import json
        import numpy as np
        from jointdyn import fourier
        c = np.array([0.1, 1.0, -0.5, 0.25, 0.125])
        hi, lo = fourier.extrema(c, 2)
        print(json.dumps({"hi": hi.hex(), "lo": lo.hex(), "hits": sum(fourier._extrema.stats.cache_hits.values())}))
        """
    )
    first, _ = _run(["-c", script])  # compiles into the cache when it is cold
    second, names = _run(["-c", script])
    a, b = json.loads(first), json.loads(second)
    assert (a["hi"], a["lo"]) == (b["hi"], b["lo"])
    assert b["hits"] == 1, "the second process did not load the kernel from the cache"
    assert not _imported(names, COMPILER_ONLY), _imported(names, COMPILER_ONLY)


def test_hb_command_imports():
    """``jointdyn frc --method hb --json``, run a second time: neither Numba's compiler nor the
    libraries of files, plots, progress bars and distributed sweeps are imported."""
    first, _ = _run(["-m", "jointdyn", *HB_ARGS])
    second, names = _run(["-m", "jointdyn", *HB_ARGS])
    assert json.loads(first) == json.loads(second)
    assert not _imported(names, NOT_FOR_HB_JSON), _imported(names, NOT_FOR_HB_JSON)
    assert not _imported(names, COMPILER_ONLY), _imported(names, COMPILER_ONLY)
    assert not _imported(names, ENVIRONMENT_ONLY), _imported(names, ENVIRONMENT_ONLY)


def test_environment_rebuilt_without_import_still_compiles_and_caches():
    """After a cached load (environments rebuilt without their modules), Numba's own rebuilder is back,
    the rebuilt environments can be pickled into a cache again, and a new function that contains the
    same Numba helpers compiles and runs."""
    script = textwrap.dedent(
        """
        import json
        import numba
        import numba.core.environment as E
        import numpy as np
        from jointdyn import _jit, fourier
        c = np.array([0.1, 1.0, -0.5, 0.25, 0.125])
        fourier.extrema(c, 2)
        restored = E._rebuild_env is _jit._NUMBA_REBUILD_ENV
        envs = list(E.Environment._memo.values())
        cacheable = all(e.can_cache() for e in envs)

        @numba.njit
        def fresh(n):
            a = np.zeros(n)
            a[:] = 0.5
            return a.sum()

        print(json.dumps({"restored": restored, "cacheable": cacheable, "n": len(envs), "fresh": fresh(4)}))
        """
    )
    _run(["-c", script])
    out, names = _run(["-c", script])
    got = json.loads(out)
    assert got == {"restored": True, "cacheable": True, "n": got["n"], "fresh": 2.0} and got["n"] > 0


def test_process_entry_freezes_what_lives_until_exit():
    """The console script and ``python -m jointdyn`` run :func:`jointdyn.cli.console`, which leaves the
    objects alive after the command to the interpreter's exit (``gc.freeze``); ``main`` does not."""
    import tomllib

    with open(Path(SRC).parent / "pyproject.toml", "rb") as fh:
        assert tomllib.load(fh)["project"]["scripts"]["jointdyn"] == "jointdyn.cli:console"
    main_py = (Path(SRC) / "jointdyn" / "__main__.py").read_text()
    assert "sys.exit(console())" in main_py
    script = textwrap.dedent(
        """
        import gc, sys
        from jointdyn.cli import console, main
        sys.argv = ["jointdyn", "--version"]
        try:
            main()
        except SystemExit:
            pass
        after_main = gc.get_freeze_count()
        try:
            console()
        except SystemExit:
            pass
        print(after_main, gc.get_freeze_count())
        """
    )
    out, _ = _run(["-c", script])
    after_main, after_console = map(int, out.splitlines()[-1].split())  # after the two version lines
    assert after_main == 0 and after_console > 0
