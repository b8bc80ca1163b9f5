"""Sphinx configuration of the jointdyn documentation site.

Build (warnings are errors, as in ``tests/test_docs.py``)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Pages are Markdown (MyST). The API reference is generated at every build
from ``jointdyn.__all__`` and the ``__all__`` of each public module (see
:func:`write_api_pages`), so it follows the code without editing. The gallery
runs every script of ``examples/``.
"""

from __future__ import annotations

import enum
import importlib
import inspect
import os
import pkgutil
import re
import shutil
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT / "src"))
os.environ.setdefault("MPLBACKEND", "Agg")

import jointdyn  # noqa: E402

project = "jointdyn"
author = "The jointdyn developers"
copyright = "2026, The jointdyn developers"
release = jointdyn.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = [
    "_build",
    "scripts",
    "img",
    # the package index's copy of README.md (docs/scripts/long_description.py)
    "long-description.md",
    "api/generated/cli.md",
    "sg_execution_times.rst",
    "auto_examples/*.ipynb",
    "auto_examples/*.py",
    "auto_examples/*.zip",
    "auto_examples/*.md5",
]

# --- MyST -------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
# links such as [text](model.md) between pages, and to files of the repository
myst_all_links_external = False

# --- autodoc / numpydoc -------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
# no "members" default here: it would override the ``:members:`` of the
# class template (docs/_templates/autosummary/class.rst), and the class pages
# would list no method or property (tests/test_docs.py checks they do)
autodoc_default_options: dict[str, object] = {}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- gallery ------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"__init__\.py|/data/",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "reset_modules": ("matplotlib",),
    "remove_config_comments": True,
    "write_computation_times": False,
    "show_signature": False,
}

# --- HTML -------------------------------------------------------------------
html_theme = "furo"
html_title = f"jointdyn {release}"
html_static_path: list[str] = []
html_show_sourcelink = False


# ------------------------------------------------------------------------------
# API reference: one page per public module, written before the build reads
# its sources
# ------------------------------------------------------------------------------
#: modules that are not a Python API: the command line has its own page
_NOT_API = {"cli", "commands"}
API_DIR = DOCS / "api" / "generated"


def public_modules() -> list[str]:
    """``jointdyn`` and its modules and packages whose name has no leading underscore."""
    names = ["jointdyn"]
    for info in sorted(pkgutil.iter_modules(jointdyn.__path__), key=lambda i: i.name):
        if not info.name.startswith("_") and info.name not in _NOT_API:
            names.append(f"jointdyn.{info.name}")
    return names


def _key(obj, name: str) -> int:
    """Identity of an exported object; small constants (which can share an
    identity with an unrelated constant) are told apart by their name."""
    if isinstance(obj, (int, float, str, bool, tuple, dict, frozenset)) and not callable(obj):
        return hash((id(obj), name))
    return id(obj)


def _canonical(modules: list[str]) -> dict[int, str]:
    """Object key -> the one qualified name under which it is documented: the
    first module (in :func:`public_modules` order) whose ``__all__`` lists it."""
    home: dict[int, str] = {}
    for modname in modules:
        mod = importlib.import_module(modname)
        for name in getattr(mod, "__all__", ()):
            home.setdefault(_key(getattr(mod, name), name), f"{modname}.{name}")
    return home


def _module_page(modname: str, home: dict[int, str]) -> str:
    mod = importlib.import_module(modname)
    title = f"``{modname}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {modname}", "   :no-members:", ""]
    # exported submodules have their own pages (an autosummary entry would
    # overwrite that page with a generated stub)
    names = [n for n in getattr(mod, "__all__", ()) if not inspect.ismodule(getattr(mod, n))]
    if not hasattr(mod, "__all__"):
        # no __all__: the module's documented names (docstrings, ``#:`` comments)
        lines[-2] = "   :members:"
        return "\n".join(lines)
    own = [n for n in names if home[_key(getattr(mod, n), n)] == f"{modname}.{n}"]
    elsewhere = [home[_key(getattr(mod, n), n)] for n in names if n not in own]
    if own:
        lines += [f".. currentmodule:: {modname}", "", ".. autosummary::", "   :toctree: .", ""]
        lines += [f"   {n}" for n in own]
        lines.append("")
    if elsewhere:
        lines += ["Also exported here, documented where they are first exported:", "",
                  ".. autosummary::", ""]
        lines += [f"   ~{q}" for q in elsewhere]
        lines.append("")
    return "\n".join(lines)


def write_api_pages() -> list[str]:
    """Write ``api/generated/<module>.rst`` for every public module and
    ``api/generated/toc.txt``, the toctree that ``api/index.md`` includes.

    The folder is rebuilt at every build, so that a removed module or name
    leaves no stale page behind. Returns the module names.
    """
    modules = public_modules()
    home = _canonical(modules)
    shutil.rmtree(API_DIR, ignore_errors=True)
    API_DIR.mkdir(parents=True)
    for modname in modules:
        (API_DIR / f"{modname}.rst").write_text(_module_page(modname, home))
    toc = ["```{toctree}", ":maxdepth: 1", ""] + [f"generated/{m}" for m in modules] + ["```", ""]
    (API_DIR / "toc.txt").write_text("\n".join(toc))
    (API_DIR / "cli.md").write_text(cli_help())
    return modules


def cli_help() -> str:
    """``jointdyn --help`` and ``jointdyn <command> --help`` as Markdown sections."""
    from jointdyn.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    out = ["## `jointdyn`", "", "```text", parser.format_help().rstrip(), "```", ""]
    for name, p in sub.choices.items():
        out += [f"## `jointdyn {name}`", "", "```text", p.format_help().rstrip(), "```", ""]
    return "\n".join(out)


# ------------------------------------------------------------------------------
# Docstrings write absolute values as |x|, which reStructuredText would read
# as a substitution reference: escape the bars outside literal text
# ------------------------------------------------------------------------------
_LITERAL = re.compile(r"(``.*?``|:math:`[^`]*`|`[^`]*`)")


def _escape_bars(line: str) -> str:
    parts = _LITERAL.split(line)
    return "".join(p if i % 2 else re.sub(r"(?<!\\)\|", r"\\|", p) for i, p in enumerate(parts))


def escape_absolute_values(app, what, name, obj, options, lines):
    """``autodoc-process-docstring`` handler: ``|`` -> ``\\|`` except in
    literal and math blocks (after a line ending in ``::``), inline literals,
    and rows of grid tables and line blocks."""
    block = None  # indentation of the line that opened a literal block
    for i, line in enumerate(lines):
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if block is not None:
            if not stripped or indent > block:
                continue
            block = None
        if stripped.endswith("::"):
            block = indent
        table_row = re.match(r"^(\| |[+|].*[+|]$)", stripped)
        if "|" in line and not table_row:
            lines[i] = _escape_bars(line)


def constant_values(app, what, name, obj, options, lines):
    """``autodoc-process-docstring`` handler: a module constant (an int,
    tuple, dict...) has no docstring of its own, and autodoc would show its
    type's (``int([x]) -> integer``); show its value instead."""
    own = type(obj).__doc__
    if not isinstance(own, str):  # a named tuple's field: its type's __doc__ is a slot descriptor
        return
    if what in ("data", "attribute") and own and lines and lines[0].strip() == own.strip().splitlines()[0].strip():
        text = repr(obj)
        lines[:] = [f"Value: ``{text if len(text) <= 300 else text[:300] + ' ...'}``"]


def enum_members(app, what, name, obj, skip, options):
    """``autodoc-skip-member`` handler: the members of a status enumeration
    (``PERIODIC``, ``COMPLETE`` ...) have no docstring of their own, so
    autodoc would leave them out, but they are what a user compares results
    with: list them (with their values)."""
    if what == "class" and isinstance(obj, enum.Enum):
        return False
    return None


def status_messages(app, what, name, obj, options, lines):
    """``autodoc-process-docstring`` handler: a status enumeration's page
    says what each of its members means (its ``message``), which the
    members' own entries cannot (they have no docstring)."""
    if what == "class" and isinstance(obj, type) and issubclass(obj, enum.Enum) and len(obj):
        if all(isinstance(getattr(m, "message", None), str) for m in obj):
            lines += ["", "Members, their values and what they mean:", ""]
            lines += [f"- ``{m.name}`` (``{m.value!r}``): {m.message}" for m in obj] + [""]


def setup(app):
    app.connect("autodoc-skip-member", enum_members)
    # after numpydoc (priority 500), before the bars are escaped (600)
    app.connect("autodoc-process-docstring", status_messages, priority=550)
    # the API pages are written before autosummary reads them (builder-inited);
    # here rather than at import, so that tests can import this file
    write_api_pages()
    app.connect("autodoc-process-docstring", constant_values, priority=400)
    # after numpydoc (priority 500) has turned the sections into reST
    app.connect("autodoc-process-docstring", escape_absolute_values, priority=600)
