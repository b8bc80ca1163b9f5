"""Figure registry: compute data, save it, plot from the saved data.

A figure is registered by name with two functions:

``compute() -> dict[str, pandas.DataFrame]``
    the numbers, as named tables;
``plot(tables, out_dir) -> list[Path]``
    draws PNG (and SVG) files from the tables as read back from CSV.

:func:`make_figure` runs compute, writes ``<name>_<table>.csv`` atomically,
reads them back and calls plot, so every picture is reproducible from the
data beside it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pandas as pd

from .._io import atomic_path

__all__ = ["Figure", "register_figure", "figure_names", "make_figure", "FIGURES", "pyplot", "save_figure",
           "model_label", "math_text", "use_math_text"]

def model_label(model: str) -> str:
    """Name of a contact law in a figure: its label registered with the law
    (:func:`jointdyn.laws.law_label`) and its registered name, e.g.
    ``"exact Iwan model (iwan)"``; the name alone for a law registered
    without a label, or for a name that is not registered."""
    from ..laws import law_label, law_names

    label = law_label(model) if model in law_names() else model
    return f"{label} ({model})" if label != model else str(model)


#: Greek letters that titles, labels and legends spell out (eta, gamma, ...)
_GREEK = ("alpha", "beta", "gamma", "delta", "zeta", "eta", "theta", "mu", "omega")
#: a Greek word, the unit um, w0 and the w of "w / w0", each a whole word
_MATH_WORD = re.compile(r"\b(?:" + "|".join(_GREEK) + r"|um|w0)\b|\bw(?= / )")
#: a mathtext segment already in a text
_MATH_SEGMENT = re.compile(r"(\$[^$]*\$)")


def _math_word(match) -> str:
    word = match.group(0)
    if word == "um":
        return r"$\mu$m"
    if word == "w0":
        return r"$\omega_0$"
    if word == "w":
        return r"$\omega$"
    return rf"$\{word}$"


def math_text(text: str) -> str:
    """``text`` with its spelled-out Greek letters (``eta``, ``gamma``, ...),
    the unit ``um`` and the ``w / w0`` of a frequency ratio in matplotlib's
    mathtext (``$\\eta$``, ``$\\mu$m``, ``$\\omega / \\omega_0$``).

    Only whole words change (``delta_deg``, ``beta1`` and ``maximum`` stay),
    and mathtext already in the text is left as it is.
    """
    parts = _MATH_SEGMENT.split(text)
    return "".join(p if i % 2 else _MATH_WORD.sub(_math_word, p) for i, p in enumerate(parts))


def use_math_text(fig) -> None:
    """Apply :func:`math_text` to every text of ``fig`` (titles, axis labels,
    legends, annotations), so that pictures show eta as the letter."""
    from matplotlib.text import Text

    for text in fig.findobj(Text):
        old = text.get_text()
        new = math_text(old) if old else old
        if new != old:
            text.set_text(new)


class _Registry(dict):
    """Name -> Figure; reading it first imports every figure module, so a
    lookup such as ``FIGURES["fig6"]`` works without a prior
    :func:`figure_names` call."""

    def _full(self):
        _load_all()
        return self

    def __getitem__(self, name):
        return dict.__getitem__(self._full(), name)

    def __contains__(self, name):
        return dict.__contains__(self._full(), name)

    def __iter__(self):
        return dict.__iter__(self._full())

    def __len__(self):
        return dict.__len__(self._full())

    def get(self, name, default=None):
        return dict.get(self._full(), name, default)

    def keys(self):
        return dict.keys(self._full())

    def values(self):
        return dict.values(self._full())

    def items(self):
        return dict.items(self._full())


FIGURES: dict[str, "Figure"] = _Registry()


@dataclass(frozen=True)
class Figure:
    name: str
    title: str
    compute: Callable[[], dict]
    plot: Callable[[dict, Path], list]
    order: int = 100


def register_figure(name: str, title: str, order: int = 100):
    """Decorator for a ``compute`` function; its ``.plot`` attribute is set by
    ``@<compute>.plotter``."""

    def deco(compute):
        holder = {}

        def plotter(plot):
            FIGURES[name] = Figure(name=name, title=title, compute=compute, plot=plot, order=order)
            holder["plot"] = plot
            return plot

        compute.plotter = plotter
        return compute

    return deco


def figure_names() -> list[str]:
    _load_all()
    return [f.name for f in sorted(FIGURES.values(), key=lambda f: (f.order, f.name))]


_LOADED = []


def _load_all() -> None:
    if _LOADED:
        return
    import importlib
    import pkgutil

    # this package's directory (the package itself is not imported back from here)
    for info in pkgutil.iter_modules([str(Path(__file__).parent)]):
        if not info.name.startswith("_"):
            importlib.import_module(f"{__package__}.{info.name}")
    _LOADED.append(True)


def make_figure(name: str, out_dir) -> list[Path]:
    """Compute, save and plot one registered figure; returns written paths."""
    _load_all()
    if name not in FIGURES:
        raise ValueError(f"figure must be one of {', '.join(figure_names())}; got {name!r}")
    fig = FIGURES[name]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    tables = fig.compute()
    written = []
    for key, df in tables.items():
        path = out / f"{name}_{key}.csv"
        with atomic_path(path) as tmp:
            df.to_csv(tmp, index=False)
        written.append(path)
    saved = {key: pd.read_csv(out / f"{name}_{key}.csv") for key in tables}
    written += [Path(p) for p in fig.plot(saved, out)]
    return written


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, out_dir, name: str, dpi: int = 130) -> list[Path]:
    """Write ``fig`` as ``<name>.png`` (at ``dpi``) and ``<name>.svg``, atomically,
    its texts in mathtext (:func:`use_math_text`); close it."""
    use_math_text(fig)
    paths = []
    for ext in ("png", "svg"):
        path = Path(out_dir) / f"{name}.{ext}"
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi if ext == "png" else None)
        paths.append(path)
    pyplot().close(fig)
    return paths
