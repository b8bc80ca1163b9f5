"""The benchmarks (and docs/scripts) still name what jointdyn has: every jointdyn name they import or
reach by attribute exists, every keyword they pass to a jointdyn function or class is one it takes, and
every name they import from a module beside them is defined there.

The benchmarks call private functions and options objects by name; when a name moves (a module constant
into an options object, a function into another module) a benchmark breaks only when it is run, which takes
minutes to hours (``benchmarks/run.py``). This reads their source (nothing is run): imports of ``jointdyn``
modules and names, attribute chains on those (``hb_branch.growths``, ``jd.hb.HBOptions``) and keyword
arguments of calls to them, resolved against the installed package.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import types
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = sorted([*(ROOT / "benchmarks").glob("*.py"), *(ROOT / "docs" / "scripts").glob("*.py")])


def _import(module: str, name: str | None = None):
    """The module ``module``, or its attribute (or submodule) ``name``; LookupError naming what is missing."""
    try:
        mod = importlib.import_module(module)
    except ImportError as e:
        raise LookupError(f"module {module} ({e})") from None
    if name is None:
        return mod
    if hasattr(mod, name):
        return getattr(mod, name)
    try:
        return importlib.import_module(f"{module}.{name}")
    except ImportError:
        raise LookupError(f"{module}.{name}") from None


def _sibling_errors(node) -> list[str]:
    """Names imported from another module beside the benchmarks (``from bench_hb_scale import _system``,
    ``from _isolated import isolated``) that it does not define at its top level."""
    if not (isinstance(node, ast.ImportFrom) and node.level == 0 and node.module):
        return []
    for folder in {p.parent for p in SOURCES}:
        path = folder / f"{node.module}.py"
        if path.exists():
            top = set()
            for n in ast.parse(path.read_text()).body:
                if isinstance(n, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)):
                    top.add(n.name)
                elif isinstance(n, (ast.Assign, ast.AnnAssign)):
                    targets = n.targets if isinstance(n, ast.Assign) else [n.target]
                    top |= {e.id for t in targets for e in ast.walk(t) if isinstance(e, ast.Name)}
                elif isinstance(n, (ast.Import, ast.ImportFrom)):
                    top |= {(a.asname or a.name).split(".")[0] for a in n.names}
            return [f"line {node.lineno}: no {node.module}.{a.name}" for a in node.names if a.name not in top]
    return []


def _bindings(tree):
    """(local name -> [objects], errors) from the jointdyn imports anywhere in the file."""
    names, errors = {}, []
    for node in ast.walk(tree):
        errors += _sibling_errors(node)
        try:
            if isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.split(".")[0] == "jointdyn":
                        obj = _import(a.name)
                        key = a.asname or a.name.split(".")[0]
                        names.setdefault(key, []).append(obj if a.asname else _import("jointdyn"))
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module \
                    and node.module.split(".")[0] == "jointdyn":
                for a in node.names:
                    names.setdefault(a.asname or a.name, []).append(_import(node.module, a.name))
        except LookupError as e:
            errors.append(f"line {node.lineno}: no {e}")
    return names, errors


def _resolve(node, names):
    """The objects an expression ``a.b.c`` names when ``a`` is a jointdyn binding; LookupError when an
    attribute of a jointdyn module is missing; [] for anything else."""
    if isinstance(node, ast.Name):
        return names.get(node.id, [])
    if isinstance(node, ast.Attribute):
        out = []
        for base in _resolve(node.value, names):
            if isinstance(base, types.ModuleType) or inspect.isclass(base):
                if not hasattr(base, node.attr):
                    try:
                        out.append(importlib.import_module(f"{base.__name__}.{node.attr}"))
                        continue
                    except (ImportError, AttributeError):
                        raise LookupError(f"{getattr(base, '__name__', base)}.{node.attr}") from None
                out.append(getattr(base, node.attr))
        return out
    return []


def _keyword_errors(call, targets):
    """Keywords of ``call`` that a jointdyn callable among ``targets`` does not take."""
    errors = []
    kws = [k.arg for k in call.keywords if k.arg is not None]
    for f in targets:
        if not callable(f) or not getattr(f, "__module__", "").startswith("jointdyn"):
            continue
        try:
            sig = inspect.signature(f)
        except (TypeError, ValueError):
            continue
        if any(p.kind is p.VAR_KEYWORD for p in sig.parameters.values()):
            continue
        bad = [k for k in kws if k not in sig.parameters]
        if bad:
            errors.append(f"line {call.lineno}: {getattr(f, '__qualname__', f)} takes no {', '.join(bad)}")
    return errors


def _problems(tree) -> list[str]:
    """Every jointdyn name in ``tree`` that does not resolve and every keyword not taken."""
    names, errors = _bindings(tree)
    for node in ast.walk(tree):
        try:
            if isinstance(node, ast.Attribute):
                _resolve(node, names)
            elif isinstance(node, ast.Call):
                errors += _keyword_errors(node, _resolve(node.func, names))
        except LookupError as e:
            errors.append(f"line {node.lineno}: no {e}")
    return sorted(set(errors))


@pytest.mark.parametrize("path", SOURCES, ids=[p.name for p in SOURCES])
def test_benchmark_names_resolve(path):
    errors = _problems(ast.parse(path.read_text(), filename=str(path)))
    assert not errors, f"{path.name}: " + "; ".join(errors)


def test_the_check_finds_a_moved_name_and_a_renamed_keyword():
    """The check catches what broke benchmarks before: a private function that moved, an options field
    that was renamed."""
    src = ("import jointdyn.hb.branch as hb_branch\nfrom jointdyn.hb import HBOptions\n"
           "from jointdyn.hb.branch import _dense_growth\n"
           "f = hb_branch._arnoldi_growth\no = HBOptions(hill_max_rows=0, fold_window=3)\n")
    text = "; ".join(_problems(ast.parse(src)))
    assert "jointdyn.hb.branch._dense_growth" in text and "jointdyn.hb.branch._arnoldi_growth" in text
    assert "takes no hill_max_rows" in text and "fold_window" not in text
    # a helper that moved out of a sibling benchmark (what broke bench_modal_damping once)
    text = "; ".join(_problems(ast.parse("from bench_hb_scale import _compare_backbones, _isolated\n")))
    assert "bench_hb_scale._isolated" in text and "_compare_backbones" not in text
