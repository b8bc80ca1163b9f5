"""The architecture as rules that can fail: function length and import direction.

The layers of the package, imports pointing one way (a module may import its
own layer and the layers below it, never one above)::

    cli, commands, figures                        (front ends)
    sweeps                                        (many points, processes, files)
    dynamics, hb, modes                           (solvers)
    continuation, drivers                         (generic continuation, quasi-static drivers)
    systems, kinematics, fourier, files, ...     (what a structure and its contacts are)
    laws                                          (contact laws)

Helpers used everywhere (configuration, statuses, the jit helper, caches,
validation, atomic file writing) belong to no layer.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "jointdyn"

#: the longest function body allowed, in lines, its docstring excluded
MAX_FUNCTION_LINES = 100

#: layer of each top-level module or package of jointdyn (higher imports lower)
LAYERS = {
    "laws": 0,
    "systems": 1, "kinematics": 1, "fourier": 1, "reduction": 1, "systemfile": 1, "files": 1,
    "continuation": 2, "drivers": 2,
    "dynamics": 3, "hb": 3, "modes": 3, "identify": 3,
    "sweeps": 4,
    "cli": 5, "commands": 5, "figures": 5, "__main__": 5,
}
#: helpers outside the layers, importable from anywhere
UTILITIES = {"config", "status", "_jit", "_cache", "_validate", "_io", "version"}


def _modules():
    return sorted(p for p in SRC.rglob("*.py") if "__pycache__" not in p.parts)


def _top(path: Path) -> str:
    rel = path.relative_to(SRC)
    return rel.parts[0].removesuffix(".py")


def _function_lengths(tree: ast.AST):
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if (body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
                    and isinstance(body[0].value.value, str)):
                body = body[1:]
            if not body:
                continue
            yield node.name, node.lineno, body[-1].end_lineno - body[0].lineno + 1


def test_no_function_longer_than_the_limit():
    long = []
    for path in _modules():
        tree = ast.parse(path.read_text(), str(path))
        for name, line, n in _function_lengths(tree):
            if n > MAX_FUNCTION_LINES:
                long.append(f"{path.relative_to(SRC)}:{line} {name}: {n} lines")
    assert not long, "\n".join(long)


def _imported_tops(tree: ast.AST, path: Path):
    """Top-level jointdyn modules imported by one file (relative imports resolved)."""
    package = list(path.relative_to(SRC).parent.parts)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if parts[0] == "jointdyn" and len(parts) > 1:
                    yield parts[1], node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)] if node.level > 1 else package
                parts = base + (node.module.split(".") if node.module else [])
            elif node.module and node.module.split(".")[0] == "jointdyn":
                parts = node.module.split(".")[1:]
            else:
                continue
            if parts:
                yield parts[0], node.lineno
            else:  # ``from . import x`` / ``from jointdyn import x``
                for alias in node.names:
                    yield alias.name, node.lineno


def test_every_module_has_a_layer():
    tops = {_top(p) for p in _modules()} - {"__init__"}
    assert not tops - set(LAYERS) - UTILITIES, "add these modules to LAYERS or UTILITIES"


def test_imports_point_down_the_layers():
    wrong = []
    for path in _modules():
        top = _top(path)
        if top not in LAYERS:
            continue
        tree = ast.parse(path.read_text(), str(path))
        for target, line in _imported_tops(tree, path):
            if target in UTILITIES or target not in LAYERS:
                continue
            if LAYERS[target] > LAYERS[top]:
                wrong.append(f"{path.relative_to(SRC)}:{line} ({top}) imports {target}")
    assert not wrong, "\n".join(wrong)


@pytest.mark.parametrize("sub", ["dynamics", "hb", "continuation", "sweeps"])
def test_generic_layers_import_no_specific_law(sub):
    paths = [SRC / f"{sub}.py"] if (SRC / f"{sub}.py").exists() else sorted((SRC / sub).rglob("*.py"))
    offenders = []
    for path in paths:
        text = path.read_text()
        for name in ("laws.exact", "laws.iwan_closed", "laws.discrete", "laws.jenkins", "import Jenkins",
                     "import DiscreteIwan", "import Iwan"):
            if name in text:
                offenders.append(f"{path.relative_to(SRC)}: {name}")
    assert not offenders, "\n".join(offenders)
