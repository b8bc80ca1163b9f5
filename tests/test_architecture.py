"""The architecture as rules that can fail: function and module length, import direction, no import circle.

The layers of the package, imports pointing one way (a module may import its
own layer and the layers below it, never one above)::

    cli, commands, figures                        (front ends)
    sweeps, validation                            (many points, processes, files; validation studies)
    dynamics, hb, modes                           (solvers)
    continuation, drivers                         (generic continuation, quasi-static drivers)
    systems, kinematics, fourier, files, reduction (what a structure and its contacts are)
    laws                                          (contact laws)

Helpers used everywhere (configuration, statuses, the jit helper, caches,
validation, atomic file writing, exit codes) belong to no layer. No module
imports itself back through others, at module level or inside a function.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "jointdyn"

#: the longest function body allowed, in lines, its docstring excluded
MAX_FUNCTION_LINES = 100
#: the longest module allowed, in lines
MAX_MODULE_LINES = 900

#: layer of each top-level module or package of jointdyn (higher imports lower)
LAYERS = {
    "laws": 0,
    "systems": 1, "kinematics": 1, "interfaces": 1, "fourier": 1, "reduction": 1, "files": 1,
    "continuation": 2, "drivers": 2,
    "dynamics": 3, "hb": 3, "modes": 3,
    "sweeps": 4, "validation": 4,
    "cli": 5, "commands": 5, "figures": 5, "__main__": 5,
}
#: helpers outside the layers, importable from anywhere
UTILITIES = {"config", "status", "_jit", "_cache", "_validate", "_io", "_exit"}


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


def test_the_layer_table_names_only_existing_modules():
    tops = {_top(p) for p in _modules()}
    assert not (set(LAYERS) | UTILITIES) - tops, "remove these names from LAYERS or UTILITIES"


def test_no_module_longer_than_the_limit():
    long = [f"{p.relative_to(SRC)}: {n} lines" for p in _modules()
            if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES]
    assert not long, "\n".join(long)


def _module_name(path: Path, root: Path = SRC) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imported_modules(tree: ast.AST, path: Path, root: Path, modules) -> set:
    """The jointdyn modules one file imports, anywhere in it (inside functions too): ``from .x import y``
    names the submodule x.y where it is one, else x."""
    name = _module_name(path, root)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names if alias.name.split(".")[0] == "jointdyn"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package[: len(package) - (node.level - 1)] + ([node.module] if node.module else []))
            elif node.module and node.module.split(".")[0] == "jointdyn":
                base = node.module
            else:
                continue
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base for alias in node.names]
        else:
            continue
        for target in targets:
            while target not in modules and "." in target:
                target = target.rsplit(".", 1)[0]
            if target in modules and target != name:
                out.add(target)
    return out


def import_graph(root: Path = SRC) -> dict:
    """Module name -> the jointdyn modules it imports (module level and inside functions)."""
    paths = {_module_name(p, root): p for p in sorted(q for q in root.rglob("*.py") if "__pycache__" not in q.parts)}
    return {m: _imported_modules(ast.parse(p.read_text(), str(p)), p, root, paths) for m, p in paths.items()}


def import_circles(graph: dict) -> list:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(graph) + 100))

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    try:
        for v in sorted(graph):
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return out


def test_no_import_circle():
    circles = import_circles(import_graph())
    assert not circles, "\n".join(" <-> ".join(c) for c in circles)


def test_the_circle_check_finds_a_late_import(tmp_path):
    # a circle closed by an import inside a function is a circle: the check must see it
    pkg = tmp_path / "jointdyn"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "a.py").write_text("from .b import f\n")
    (pkg / "sub" / "b.py").write_text("def f():\n    from .a import g\n    return g\n")
    (pkg / "c.py").write_text("from .sub import a\n")
    assert import_circles(import_graph(pkg)) == [["jointdyn.sub.a", "jointdyn.sub.b"]]


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
        for name in ("laws.exact", "laws.iwan_closed", "laws.discrete", "import Jenkins",
                     "import DiscreteIwan", "import Iwan"):
            if name in text:
                offenders.append(f"{path.relative_to(SRC)}: {name}")
    assert not offenders, "\n".join(offenders)
