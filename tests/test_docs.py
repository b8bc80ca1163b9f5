"""The documentation: the site builds with warnings as errors and runs every
gallery example; the code of the getting-started and guide pages runs; no
file refers to a path outside the repository; relative links resolve.

The two slow tests carry the ``docs`` marker (``pytest -m "not docs"``
leaves them out locally); they run by default.
"""

from __future__ import annotations

import enum
import functools
import importlib
import importlib.util
import inspect
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: copied beside docs/ for a build in a scratch folder (the pages include or link these)
BUILD_INPUTS = ("docs", "examples", "CHANGELOG.md", "README.md")
#: build outputs inside docs/ that a copy must not carry along
_OUTPUTS = shutil.ignore_patterns("_build", "auto_examples", "generated", "sg_execution_times.rst", "__pycache__")


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["MPLBACKEND"] = "Agg"
    return env


@pytest.mark.docs
def test_site_builds_strict_and_runs_the_gallery(tmp_path):
    src = tmp_path / "src"
    for name in BUILD_INPUTS:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, ignore=_OUTPUTS)
        else:
            shutil.copy2(path, src / name)
    out = tmp_path / "html"
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(src / "docs"), str(out)]
    proc = subprocess.run(cmd, cwd=tmp_path, env=_env(), capture_output=True, text=True)
    warnings = [line for line in proc.stderr.splitlines() if "WARNING" in line or "ERROR" in line]
    assert proc.returncode == 0, "\n".join(warnings) or proc.stderr[-5000:]
    # every example ran and has its page
    for script in (ROOT / "examples").glob("plot_*.py"):
        page = out / "auto_examples" / f"{script.stem}.html"
        assert page.is_file(), f"gallery page missing for {script.name}"
    # every public name of the package has its anchor in the API reference
    import jointdyn

    api = "".join(p.read_text() for p in (out / "api" / "generated").glob("*.html"))
    missing = [n for n in jointdyn.__all__ if f'id="jointdyn.{n}"' not in api
               and f'id="module-jointdyn.{n}"' not in api
               and not re.search(rf'id="jointdyn\.[a-z_]+\.{re.escape(n)}"', api)]
    assert not missing, f"public names without an API entry: {missing}"
    # every public method, property and status member of every public class has its entry
    missing = [f"{q}.{m}" for q, cls in _public_classes().items() for m in _public_members(cls)
               if f'id="{q}.{m}"' not in api]
    assert not missing, f"public members without an API entry: {missing}"


def _docs_conf():
    """docs/conf.py as a module (importing it writes nothing: the pages are
    written by its ``setup``)."""
    spec = importlib.util.spec_from_file_location("jointdyn_docs_conf", DOCS / "conf.py")
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    return conf


def _public_classes() -> dict:
    """Qualified name under which each public class is documented -> the class."""
    conf = _docs_conf()
    classes = {}
    for q in sorted(set(conf._canonical(conf.public_modules()).values())):
        modname, name = q.rsplit(".", 1)
        obj = getattr(importlib.import_module(modname), name)
        if inspect.isclass(obj):
            classes[q] = obj
    return classes


def _public_members(cls) -> list[str]:
    """The members a user calls or reads, defined by jointdyn (on ``cls`` or a
    base): methods, properties, class and static methods, and the members of
    a status enumeration. Fields of dataclasses are described in the class's
    docstring instead."""
    kinds = (property, functools.cached_property, classmethod, staticmethod)
    names = []
    for name in dir(cls):
        owner = next((c for c in cls.__mro__ if name in c.__dict__), None)
        if name.startswith("_") or owner is None or not owner.__module__.startswith("jointdyn"):
            continue
        raw = owner.__dict__[name]
        if inspect.isfunction(raw) or isinstance(raw, kinds) or (issubclass(cls, enum.Enum)
                                                                 and isinstance(raw, enum.Enum)):
            names.append(name)
    return names


def _docstring(cls, name: str) -> str | None:
    """The docstring autodoc shows for a member (its own, else a base's)."""
    for c in cls.__mro__:
        raw = c.__dict__.get(name)
        if raw is None:
            continue
        raw = raw.__func__ if isinstance(raw, (classmethod, staticmethod)) else raw
        raw = raw.func if isinstance(raw, functools.cached_property) else raw
        if raw.__doc__:
            return raw.__doc__
    return None


def test_every_public_member_has_an_api_entry():
    """Fast check of what the site build shows (test_site_builds_strict_and_runs_the_gallery
    checks the anchors themselves): class pages list members (the template
    asks for them and no default switches them off, which once left every
    class page without a method), and every method and property has a
    docstring, without which autodoc leaves it out."""
    conf = _docs_conf()
    template = (DOCS / "_templates" / "autosummary" / "class.rst").read_text()
    assert ":members:" in template and ":inherited-members:" in template
    assert conf.autodoc_default_options.get("members", True) is not False
    classes = _public_classes()
    assert {"jointdyn.System", "jointdyn.LoopResult"} <= set(classes)
    assert {"paper_damper", "last_cycle"} <= set(_public_members(classes["jointdyn.System"])) | set(
        _public_members(classes["jointdyn.LoopResult"]))
    undocumented = [f"{q}.{m}" for q, cls in classes.items() for m in _public_members(cls)
                    if not isinstance(getattr(cls, m), enum.Enum) and not _docstring(cls, m)]
    assert not undocumented, f"public members without a docstring (no API entry): {undocumented}"


def _python_blocks(page: Path) -> str:
    return "\n".join(re.findall(r"```python\n(.*?)```", page.read_text(), re.S))


GUIDE_PAGES = [DOCS / "getting-started.md", *sorted((DOCS / "guide").glob("*.md"))]


@pytest.mark.docs
@pytest.mark.parametrize("page", [p for p in GUIDE_PAGES if "```python" in p.read_text()], ids=lambda p: p.name)
def test_guide_code_runs(page, tmp_path, monkeypatch, capsys):
    """The Python blocks of one page, in order, in one namespace (files land in a scratch folder)."""
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    code = _python_blocks(page)
    exec(compile(code, str(page), "exec"), {"__name__": f"docs_{page.stem}"})
    assert capsys.readouterr().out.strip(), f"{page.name} printed nothing"


def _repository_files():
    """Tracked files (a git checkout) or every file (an unpacked source distribution)."""
    git = shutil.which("git")
    if git and (ROOT / ".git").exists():
        names = subprocess.run([git, "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True).stdout
        return [ROOT / n for n in names.decode().split("\0") if n]
    skip = {".git", "__pycache__", "_build", "auto_examples", "generated", ".hypothesis", ".pytest_cache"}
    return [p for p in ROOT.rglob("*") if p.is_file() and not skip & set(p.relative_to(ROOT).parts)]


#: references to the private notes beside the repository, or to absolute paths of a machine
_OUTSIDE = re.compile(r"\.\./shared\b|/work/|(?<![\w.])shared/(MODEL|paper)|(?<![\w/])MODEL\.md")


def test_no_file_refers_outside_the_repository():
    offenders = []
    for path in _repository_files():
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, FileNotFoundError):
            continue  # binary (images) or deleted in the work tree
        for no, line in enumerate(text.splitlines(), 1):
            if _OUTSIDE.search(line) and path.name != Path(__file__).name:
                offenders.append(f"{path.relative_to(ROOT)}:{no}: {line.strip()[:100]}")
    assert not offenders, "\n".join(offenders)


_LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("page", ["README.md", "CHANGELOG.md", *[str(p.relative_to(ROOT)) for p in DOCS.glob("**/*.md")
                                  if "_build" not in p.parts and "generated" not in p.parts]])
def test_relative_links_resolve(page):
    path = ROOT / page
    broken = []
    for target in _LINK.findall(path.read_text()):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue
        file = target.split("#", 1)[0]
        if "auto_examples/" in file:  # written by the gallery at build time
            file = "../examples/" + Path(file).stem + ".py" if Path(file).stem != "index" else "../examples/README.txt"
            base = DOCS
        else:
            base = path.parent
        if not (base / file).exists():
            broken.append(target)
    assert not broken, f"{page}: links to missing files: {broken}"


#: a reference to the project's internal issue tracker ("issue 9", "issue #9")
_ISSUE = re.compile(r"\bissues? #?\d+\b", re.I)


def test_user_pages_cite_no_internal_issue_numbers():
    """README, the docs, the examples and the docstrings speak for themselves:
    an internal issue number means nothing to a user."""
    files = [ROOT / "README.md", ROOT / "CHANGELOG.md", *DOCS.glob("**/*.md"), *DOCS.glob("scripts/*.py"),
             *(ROOT / "examples").glob("*.py"), *(ROOT / "src" / "jointdyn").glob("**/*.py")]
    offenders = [f"{p.relative_to(ROOT)}:{no}: {line.strip()[:100]}"
                 for p in files if not {"_build", "generated", "auto_examples"} & set(p.parts)
                 for no, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if _ISSUE.search(line)]
    assert not offenders, "\n".join(offenders)
