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
Configuration by layer: ``config`` keeps only numbers several packages (or
the helpers) read; a number one package reads lives in that package's options
object or module.
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
    "systems": 1, "bolted": 1, "damping": 1, "kinematics": 1, "interfaces": 1, "fourier": 1, "reduction": 1, "files": 1, "fe": 1,
    "continuation": 2, "drivers": 2,
    "dynamics": 3, "hb": 3, "modes": 3, "identify": 3,
    "sweeps": 4, "validation": 4,
    "cli": 5, "commands": 5, "figures": 5, "__main__": 5,
}
#: helpers outside the layers, importable from anywhere
UTILITIES = {"config", "status", "_jit", "_cache", "_validate", "_io", "_exit", "_threads"}


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


def _near_limit_without_reason(path: Path) -> list[str]:
    """Functions of one file within 5 % of the function limit, and the file itself within 5 % of the module
    limit, whose docstring does not say why it is one piece."""
    text = path.read_text()
    tree = ast.parse(text, str(path))
    out = []
    if text.count("\n") >= 0.95 * MAX_MODULE_LINES and "one piece" not in (ast.get_docstring(tree) or "").lower():
        out.append(f"{path.relative_to(SRC)}: {text.count(chr(10))} lines")
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            n = next((n for name, line, n in _function_lengths(node) if line == node.lineno), 0)
            if n >= 0.95 * MAX_FUNCTION_LINES and "one piece" not in (ast.get_docstring(node) or "").lower():
                out.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name}: {n} lines")
    return out


def test_nothing_near_the_size_limits_without_a_reason():
    """Within 5 % of either limit, the docstring says why the function or module is one piece (a limit is a
    signal to split a concept, not a target to squeeze under)."""
    near = [item for path in _modules() for item in _near_limit_without_reason(path)]
    assert not near, "\n".join(near)


def test_near_limit_rule_catches_a_long_function(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(96))
    plain = tmp_path / "plain.py"
    plain.write_text(f'def f():\n    """Sum."""\n{body}\n')
    said = tmp_path / "said.py"
    said.write_text(f'def f():\n    """Sum, one piece: measured."""\n{body}\n')
    global SRC
    old, SRC = SRC, tmp_path
    try:
        assert _near_limit_without_reason(plain) == ["plain.py:1 f: 96 lines"]
        assert _near_limit_without_reason(said) == []
    finally:
        SRC = old


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


def _private_imports_of_other_packages(path: Path, root: Path = SRC):
    """(line, module) of each import in one file of a package that names a private module (a name
    starting with ``_``) of another package of jointdyn; the helpers outside the layers are one module
    each, not a package, and are not counted."""
    tree = ast.parse(path.read_text(), str(path))
    name = _module_name(path, root)
    own = name.split(".")[1] if "." in name else None
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)] + (node.module.split(".") if node.module else [])
            elif node.module:
                base = node.module.split(".")
            else:
                continue
            modules = [".".join(base + [alias.name]) for alias in node.names]
        else:
            continue
        for module in modules:
            parts = module.split(".")
            if parts[0] != "jointdyn" or len(parts) < 3 or parts[1] == own:
                continue
            if any(p.startswith("_") and not p.startswith("__") for p in parts[2:-1]) or (
                    parts[-1].startswith("_") and not parts[-1].startswith("__")
                    and (root / Path(*parts[1:])).with_suffix(".py").exists()):
                yield node.lineno, module


def test_commands_import_no_private_module_of_another_package():
    # the command line parses, calls public functions and writes: what it needs of a package is public
    wrong = [f"{p.relative_to(SRC)}:{line} imports {m}" for p in sorted((SRC / "commands").rglob("*.py"))
             for line, m in _private_imports_of_other_packages(p)]
    assert not wrong, "\n".join(wrong)


def test_the_private_import_check_finds_one(tmp_path):
    pkg = tmp_path / "jointdyn"
    for sub in ("commands", "dynamics"):
        (pkg / sub).mkdir(parents=True)
        (pkg / sub / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "dynamics" / "_model.py").write_text("def f():\n    pass\n")
    (pkg / "commands" / "_own.py").write_text("")
    (pkg / "commands" / "x.py").write_text("from . import _own\nfrom .. import dynamics\n"
                                           "def g():\n    from ..dynamics._model import f\n")
    found = list(_private_imports_of_other_packages(pkg / "commands" / "x.py", pkg))
    assert found == [(4, "jointdyn.dynamics._model.f")]


#: the bases that make a class an enumeration
_ENUM_BASES = {"Enum", "IntEnum", "StrEnum", "Flag", "IntFlag", "ReprEnum"}


def _base_name(node: ast.expr) -> str:
    return node.attr if isinstance(node, ast.Attribute) else getattr(node, "id", "")


def status_outside_the_base(root: Path = SRC) -> list:
    """Enumerations that do not derive from :class:`jointdyn.status.Status` (which alone derives from
    ``enum.Enum``), and classes named like a status (``...Status``, ``...Verdict``) that are not one."""
    classes = {}
    for path in sorted(q for q in root.rglob("*.py") if "__pycache__" not in q.parts):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ClassDef):
                classes[(path, node.name)] = [_base_name(b) for b in node.bases]
    family = {"Status"}
    grew = True
    while grew:  # the subclasses of Status, of their subclasses, ...
        grew = False
        for (path, name), bases in classes.items():
            if name not in family and family & set(bases) and not (path.name == "status.py" and name == "Status"):
                family.add(name)
                grew = True
    wrong = []
    for (path, name), bases in classes.items():
        rel = path.relative_to(root)
        if rel == Path("status.py") and name == "Status":
            continue
        if _ENUM_BASES & set(bases) or (name.endswith(("Status", "Verdict")) and name not in family):
            wrong.append(f"{rel}: {name}({', '.join(bases)})")
    return wrong


def test_every_status_derives_from_the_shared_base():
    # one base: every status has a message, says whether it is ok, and codes the same way
    wrong = status_outside_the_base()
    assert not wrong, "\n".join(wrong)


def test_the_status_check_finds_an_enum_of_its_own(tmp_path):
    pkg = tmp_path / "jointdyn"
    pkg.mkdir()
    (pkg / "status.py").write_text("import enum\nclass Status(str, enum.Enum):\n    pass\n")
    (pkg / "a.py").write_text("import enum\nfrom .status import Status\n"
                              "class GoodStatus(Status):\n    A = 'a', 'x', True\n"
                              "class Sub(GoodStatus):\n    pass\n"
                              "class Own(str, enum.Enum):\n    A = 'a'\n"
                              "class LoneVerdict:\n    pass\n")
    assert status_outside_the_base(pkg) == ["a.py: Own(str, Enum)", "a.py: LoneVerdict()"]


# --- the energy rule (docs/architecture.md, "Solvers and results") -------------------------------
#: a total over every element of one kind: energy_<kind>_J
ENERGY_TOTALS = {"energy_contact_J", "energy_viscous_J", "energy_interface_J"}
#: one entry per item: <item>_energy_J
ENERGY_PER_ITEM = {"contact_energy_J", "pair_energy_J", "cycle_energy_J"}
#: inside an object or a row that is one item (a contact, a pair, a cycle)
ENERGY_OF_ONE = {"energy_J"}
#: old keys written beside their new names for one release, old -> new (CHANGELOG.md, Deprecated)
ENERGY_DEPRECATED = {"energy_pairs_J": "energy_interface_J", "energy_per_cycle_J": "energy_J",
                     "energy_contact_j": "contact_energy_J"}

_ENERGY_NAME = r"\b[A-Za-z_]*energy[A-Za-z_]*_[jJ]\b"


def energy_names_outside_the_rule(root: Path = SRC) -> list:
    """Names of energies in the sources (attributes, keys, variables, text) that the rule does not
    allow."""
    import re

    allowed = ENERGY_TOTALS | ENERGY_PER_ITEM | ENERGY_OF_ONE | set(ENERGY_DEPRECATED)
    wrong = []
    for path in sorted(q for q in root.rglob("*.py") if "__pycache__" not in q.parts):
        for n, line in enumerate(path.read_text().splitlines(), 1):
            wrong += [f"{path.relative_to(root)}:{n}: {name}" for name in re.findall(_ENERGY_NAME, line)
                      if name not in allowed]
    return wrong


def test_energy_names_follow_the_documented_rule():
    wrong = energy_names_outside_the_rule()
    assert not wrong, "\n".join(wrong)


def test_the_energy_rule_is_written_down_and_the_old_keys_listed():
    root = SRC.parents[1]
    rule = (root / "docs" / "architecture.md").read_text()
    for name in ENERGY_TOTALS | ENERGY_PER_ITEM | ENERGY_OF_ONE | set(ENERGY_DEPRECATED):
        assert f"`{name}`" in rule, f"docs/architecture.md does not name {name}"
    changelog = (root / "CHANGELOG.md").read_text()
    for old, new in ENERGY_DEPRECATED.items():
        assert old in changelog and new in changelog, f"CHANGELOG.md does not list {old} -> {new}"


def test_the_energy_check_finds_a_name_outside_the_rule(tmp_path):
    pkg = tmp_path / "jointdyn"
    pkg.mkdir()
    (pkg / "a.py").write_text('d = {"energy_contact_J": 1.0, "pair_energy_J": 2.0}\n'
                              'e = {"energy_pair_total_J": 3.0}\n')
    assert energy_names_outside_the_rule(pkg) == ["a.py:2: energy_pair_total_J"]


# --- configuration by layer: config keeps only the numbers several packages share ---------------------------
#: bounds on the size of an input, kept in config beside the other input bounds whatever reads them
INPUT_BOUNDS = {"FILES_MAX_DOF"}


def config_constants(root: Path = SRC) -> set:
    """The names config.py assigns (upper case)."""
    tree = ast.parse((root / "config.py").read_text())
    return {t.id for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))
            for t in (node.targets if isinstance(node, ast.Assign) else [node.target])
            if isinstance(t, ast.Name) and t.id.isupper()}


def config_readers(root: Path = SRC) -> dict:
    """Config name -> the top-level modules and packages of jointdyn whose code reads it (``config.NAME``, or
    ``from ..config import NAME``)."""
    out = {}
    for path in sorted(q for q in root.rglob("*.py") if "__pycache__" not in q.parts and q != root / "config.py"):
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "config":
                names = [node.attr]
            elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[-1] == "config":
                names = [alias.name for alias in node.names]
            top = path.relative_to(root).parts[0].removesuffix(".py")
            for name in names:
                out.setdefault(name, set()).add(top)
    return out


def owned_config_constants(root: Path = SRC) -> dict:
    """Config name -> the one package that reads it, for every name read by one package of the layers and no
    helper (``UTILITIES``: their numbers, such as the memory bound, apply to every solver), or by nothing
    ("nobody": a number left behind)."""
    readers = config_readers(root)
    owned = {}
    for name in sorted(config_constants(root)):
        tops = readers.get(name, set())
        if tops & (UTILITIES | {"__init__"}):
            continue
        if len(tops) <= 1:
            owned[name] = next(iter(tops), "nobody")
    return owned


def test_config_keeps_only_shared_numbers():
    owned = owned_config_constants()
    crept = [f"config.{name}: read by {top} alone" for name, top in owned.items()
             if name not in INPUT_BOUNDS]
    assert not crept, ("numbers of one package belong in its options object (docs/architecture.md):\n"
                       + "\n".join(crept))
    stale = sorted(INPUT_BOUNDS - set(owned) - (INPUT_BOUNDS & config_constants()))
    assert not stale, f"moved out of config or now shared: remove from INPUT_BOUNDS: {stale}"


def test_the_config_check_finds_an_owned_number(tmp_path):
    pkg = tmp_path / "jointdyn"
    (pkg / "hb").mkdir(parents=True)
    (pkg / "modes").mkdir()
    (pkg / "config.py").write_text("SHARED = 1\nOWNED = 2\nLEFT = 3\nHELPER = 4\n")
    (pkg / "hb" / "a.py").write_text("from .. import config\nx = config.SHARED + config.OWNED\n")
    (pkg / "modes" / "b.py").write_text("from ..config import SHARED\n")
    (pkg / "_validate.py").write_text("from . import config\ny = config.HELPER\n")
    assert owned_config_constants(pkg) == {"LEFT": "nobody", "OWNED": "hb"}


# --- tests set options, not module constants ------------------------------------------------------------------
TESTS = SRC.parents[1] / "tests"
#: (module, name) of the upper-case module constants a test may still patch, with the reason: not a solver
#: number (no options object owns it)
PATCHABLE = {
    ("jointdyn.commands.frc", "SCHEDULER_TIMEOUT_S"): "the command line's wait for a Dask scheduler (a command)",
    ("jointdyn.dynamics.version", "SOLVER_VERSION"): "a format version, raised to make saved points stale",
}


def _module_names(tree: ast.AST) -> dict:
    """Local name -> dotted name of every ``import jointdyn...`` / ``from jointdyn... import x`` of a file."""
    out = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "jointdyn":
                    out[a.asname or a.name.split(".")[0]] = a.name if a.asname else "jointdyn"
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "jointdyn":
            for a in node.names:
                out[a.asname or a.name] = f"{node.module}.{a.name}"
    return out


def _dotted(node: ast.AST, names: dict):
    """The dotted name of ``a.b.c`` with ``a`` replaced by what it was imported as (None: not a name chain
    from an import of jointdyn)."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name) or node.id not in names:
        return None
    return ".".join([names[node.id], *reversed(parts)])


def _is_module(dotted: str, root: Path) -> bool:
    rel = Path(*dotted.split(".")[1:])
    return (root / rel).with_suffix(".py").is_file() or (root / rel / "__init__.py").is_file()


def patched_constants(tests: Path = TESTS, root: Path = SRC) -> list:
    """``file:line module.NAME`` of every ``setattr(module, "NAME", ...)`` (monkeypatch or a
    ``MonkeyPatch`` context) in ``tests`` that sets an upper-case constant of a jointdyn module other than
    ``config`` (the shared numbers), or ``setattr("jointdyn.module.NAME", ...)``, outside ``PATCHABLE``."""
    found = []
    for path in sorted(tests.rglob("*.py")):
        tree = ast.parse(path.read_text(), str(path))
        names = _module_names(tree)
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr == "setattr" and node.args):
                continue
            first = node.args[0]
            if isinstance(first, ast.Constant) and isinstance(first.value, str):
                module, _, name = first.value.rpartition(".")
            elif (_dotted(first, names) is not None and len(node.args) > 1
                  and isinstance(node.args[1], ast.Constant) and isinstance(node.args[1].value, str)):
                module, name = _dotted(first, names), node.args[1].value
            else:
                continue
            if (module.split(".")[0] != "jointdyn" or not name[:1].isalpha() or not name.isupper()
                    or module == "jointdyn.config" or not _is_module(module, root)
                    or (module, name) in PATCHABLE):
                continue
            found.append(f"{path.name}:{node.lineno} {module}.{name}")
    return found


def test_tests_set_options_instead_of_patching_module_constants():
    found = patched_constants()
    assert not found, ("a solver's number is a field of its options object: set it there instead of patching "
                       "the module (docs/architecture.md):\n" + "\n".join(found))


def test_the_patch_check_finds_a_patched_constant(tmp_path):
    pkg, tests = tmp_path / "jointdyn", tmp_path / "tests"
    (pkg / "hb").mkdir(parents=True)
    tests.mkdir()
    for f in ("__init__.py", "config.py", "hb/__init__.py", "hb/branch.py"):
        (pkg / f).write_text("")
    (tests / "test_x.py").write_text(
        "from jointdyn import config\nfrom jointdyn.hb import branch as hb_branch\nimport jointdyn.hb.branch\n"
        "def test_a(monkeypatch):\n"
        "    monkeypatch.setattr(config, 'SHARED', 1)\n"
        "    monkeypatch.setattr(hb_branch, 'HB_FOLD_WINDOW', 1)\n"
        "    monkeypatch.setattr(hb_branch, '_fixed_branch', None)\n"
        "    monkeypatch.setattr('jointdyn.hb.branch.HB_PEAK_PROMINENCE', 0.5)\n"
        "    monkeypatch.setattr(hb_branch.HBOptions, 'X', 1)\n"
        "    monkeypatch.setattr(jointdyn.hb.branch, 'HB_TURNING_BAND', 1)\n")
    assert patched_constants(tests, pkg) == ["test_x.py:6 jointdyn.hb.branch.HB_FOLD_WINDOW",
                                             "test_x.py:8 jointdyn.hb.branch.HB_PEAK_PROMINENCE",
                                             "test_x.py:10 jointdyn.hb.branch.HB_TURNING_BAND"]
    assert patched_constants(TESTS, SRC) == []  # (the same check on this package's tests)
