"""Release checks: the package index's long description is in sync with
README.md; ``python -m build`` makes an sdist that carries every file the
tests need and a wheel that passes ``twine check``, installs in a fresh
environment and works from any directory (``jointdyn --version``, and the
sdist's tests collect against it).

The build test carries the ``packaging`` marker. It builds in an isolated
environment, so it needs the package index (or a pip cache) for setuptools.
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
import tarfile
import venv
import zipfile
from email.parser import Parser
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "scripts"))
from long_description import TARGET, long_description  # noqa: E402

#: what the source distribution carries besides src/ (MANIFEST.in)
SDIST_DIRS = ("tests", "docs", "examples", "benchmarks")
SDIST_FILES = ("LICENSE", "README.md", "CHANGELOG.md", "pyproject.toml", "MANIFEST.in")
_SCRATCH = shutil.ignore_patterns("__pycache__", ".git", "_build", "auto_examples", "generated", "build", "dist",
                                  "*.egg-info", ".hypothesis", ".pytest_cache", "figures-out", "out", "runs",
                                  "sg_execution_times.rst")


def _version() -> str:
    """jointdyn.__version__ as written in the source (the one place it is set)."""
    tree = ast.parse((ROOT / "src" / "jointdyn" / "__init__.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "__version__" for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError("src/jointdyn/__init__.py sets no __version__")


def test_long_description_in_sync_with_readme():
    have = TARGET.read_text(encoding="utf-8")
    assert have == long_description((ROOT / "README.md").read_text(encoding="utf-8")), (
        "docs/long-description.md is out of date: run python docs/scripts/long_description.py")
    assert "](" not in have.replace("](http", "").replace("](https", ""), "relative link left in the long description"
    assert "![" not in have, "image left in the long description"


def _source_files(tree: Path) -> set[str]:
    """Files of the project tree that the sdist must carry (relative, posix)."""
    out = {f for f in SDIST_FILES if (tree / f).is_file()}
    for d in ("src", *SDIST_DIRS):
        for p in (tree / d).rglob("*"):
            if p.is_file() and "__pycache__" not in p.parts and p.suffix not in (".pyc", ".nbi", ".nbc"):
                out.add(p.relative_to(tree).as_posix())
    return out


def _test_imports(tests: Path) -> set[str]:
    """Top-level names imported by the test modules that are modules of tests/ itself."""
    local = {p.stem for p in tests.glob("*.py")}
    names = set()
    for path in tests.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names.add(node.module.split(".")[0])
    return names & local


def _fresh_env(where: Path, wheel: Path) -> Path:
    """A new virtual environment with the wheel installed (no dependencies
    fetched), which then sees this interpreter's packages for the dependencies."""
    venv.create(where, with_pip=False)
    py = where / ("Scripts" if os.name == "nt" else "bin") / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "--quiet", "--no-deps", "--no-index",
                    str(wheel)], check=True)
    site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    deps = [p for p in sys.path if p.endswith("site-packages") and Path(p).is_dir()]
    Path(site, "_parent_environment.pth").write_text("\n".join(deps) + "\n")
    return py


@pytest.mark.packaging
def test_sdist_and_wheel(tmp_path):
    tree = tmp_path / "tree"
    shutil.copytree(ROOT, tree, ignore=_SCRATCH)
    dist = tmp_path / "dist"
    build = subprocess.run([sys.executable, "-m", "build", "--outdir", str(dist), str(tree)],
                           capture_output=True, text=True)
    assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
    version = _version()
    (sdist,) = dist.glob("*.tar.gz")
    (wheel,) = dist.glob("*.whl")
    assert sdist.name == f"jointdyn-{version}.tar.gz" and wheel.name.startswith(f"jointdyn-{version}-")

    # the sdist carries the tests, every helper they import, the docs and the examples
    with tarfile.open(sdist) as tar:
        top = f"jointdyn-{version}/"
        listed = {m.name[len(top):] for m in tar.getmembers() if m.isfile()}
        tar.extractall(tmp_path / "sdist", filter="data")
    missing = sorted(_source_files(tree) - listed)
    assert not missing, f"files missing from the sdist: {missing}"
    helpers = _test_imports(tree / "tests")
    assert {"reference", "law_histories", "tolerances"} <= helpers
    assert {f"tests/{h}.py" for h in helpers} <= listed

    # metadata: SPDX license, license file, version, image-free description; twine agrees
    with zipfile.ZipFile(wheel) as zf:
        meta_name = next(n for n in zf.namelist() if n.endswith(".dist-info/METADATA"))
        meta = Parser().parsestr(zf.read(meta_name).decode())
        assert not [n for n in zf.namelist() if n.startswith("tests/")]
        assert any(n.endswith("licenses/LICENSE") for n in zf.namelist())
    assert meta["Version"] == version
    assert meta["License-Expression"] == "MIT"
    assert "![" not in meta.get_payload()
    twine = subprocess.run([sys.executable, "-m", "twine", "check", "--strict", str(sdist), str(wheel)],
                           capture_output=True, text=True)
    assert twine.returncode == 0, twine.stdout + twine.stderr

    # the wheel in a fresh environment, used from a folder that is not the repository
    py = _fresh_env(tmp_path / "env", wheel)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    where = subprocess.run([str(py), "-c", "import jointdyn; print(jointdyn.__file__, jointdyn.__version__)"],
                           cwd=elsewhere, env=env, capture_output=True, text=True, check=True).stdout.split()
    assert Path(where[0]).is_relative_to(tmp_path / "env") and where[1] == version

    # the sdist's own tests collect against the installed wheel
    collect = subprocess.run([str(py), "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"],
                             cwd=tmp_path / "sdist" / f"jointdyn-{version}", env=env, capture_output=True, text=True)
    assert collect.returncode == 0, collect.stdout[-3000:] + collect.stderr[-3000:]

    # the installed command reports the package version
    cli = py.parent / ("jointdyn.exe" if os.name == "nt" else "jointdyn")
    out = subprocess.run([str(cli), "--version"], cwd=elsewhere, env=env, capture_output=True, text=True)
    assert out.returncode == 0 and version in out.stdout, out.stdout + out.stderr


def test_gitignore_lists_no_tracked_file():
    git = shutil.which("git")
    if not (git and (ROOT / ".git").exists()):
        pytest.skip("not a git checkout (an unpacked source distribution has no .gitignore to check)")
    ignored = subprocess.run([git, "ls-files", "-ci", "--exclude-standard"], cwd=ROOT, capture_output=True,
                             text=True, check=True).stdout.split()
    assert not ignored, f".gitignore matches tracked files: {ignored}"
