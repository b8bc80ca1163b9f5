"""Where compiled kernels are cached, and what invalidates them (:mod:`jointdyn._jit`).

The cache lives outside the installed package, in a folder per jointdyn version and
Python, so that a reinstall of the same version keeps it; its files are keyed by a hash
of the sources a kernel is compiled from, its own module and the modules whose kernels
it inlines.
"""

import os
import subprocess
import sys
from pathlib import Path

import jointdyn
from jointdyn import _jit

SRC = str(Path(__file__).resolve().parents[1] / "src")
#: a hang guard for the subprocess (it compiles a small kernel), not a speed requirement
HANG_GUARD_S = 900


def test_cache_root_per_version_and_python(monkeypatch, tmp_path):
    tail = f"{jointdyn.__version__}-py{sys.version_info[0]}{sys.version_info[1]}"
    monkeypatch.setenv("JOINTDYN_CACHE_DIR", str(tmp_path / "own"))
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    assert _jit.cache_root() == os.path.join(str(tmp_path / "own"), tail)
    monkeypatch.delenv("JOINTDYN_CACHE_DIR")
    assert _jit.cache_root() == os.path.join(str(tmp_path / "numba"), "jointdyn", tail)
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    root = _jit.cache_root()
    assert root.endswith(os.path.join("jointdyn", tail)) and not root.startswith(os.path.dirname(jointdyn.__file__))


def test_stamp_covers_the_modules_a_kernel_inlines():
    import jointdyn.laws  # noqa: F401 - imports every law

    seen: set = set()
    _jit._module_files("jointdyn.laws.segalman", seen)
    assert {"jointdyn.laws.segalman", "jointdyn.laws._density_march"} <= seen
    seen = set()
    _jit._module_files("jointdyn.laws.exact", seen)
    assert "jointdyn.laws._density_march" in seen and "jointdyn.laws.segalman" not in seen
    assert _jit.source_stamp("jointdyn.laws.exact") != _jit.source_stamp("jointdyn.laws.segalman")


def test_private_march_module_is_no_law():
    from jointdyn.laws import law_names

    assert not any("density" in n or n.startswith("_") for n in law_names())


def test_kernels_go_to_the_cache_root(tmp_path):
    """A compiled kernel's files are written under the cache root (not next to the sources),
    named with the source stamp; a second process loads them."""
    env = {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", ""),
           "JOINTDYN_CACHE_DIR": str(tmp_path / "cache")}
    code = ("from jointdyn.laws import make_law; s = make_law('jenkins', kt=1.0, mu=1.0, n_ref=1.0).initial_state(0.0);"
            "print(s.size)")
    for _ in range(2):
        r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=HANG_GUARD_S)
        assert r.returncode == 0, r.stderr[-2000:]
    files = sorted(p.name for p in (tmp_path / "cache").rglob("*.nbi"))
    assert any(f.startswith("discrete.discrete_init-") for f in files), files
    stamp = subprocess.run([sys.executable, "-c", "import jointdyn.laws; from jointdyn._jit import source_stamp;"
                            "print(source_stamp('jointdyn.laws.discrete'))"], env=env, capture_output=True, text=True,
                           timeout=HANG_GUARD_S).stdout.strip()
    assert any(stamp in f for f in files), (stamp, files)
