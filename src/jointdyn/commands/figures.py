"""``jointdyn figures``: regenerate the paper's figures (data + PNG).

Each figure prints one line when it is done, terminal or not: its name, the
size of its data (rows of each CSV table) and the files written. ``--out``
is checked for writability before anything is computed.
"""

from __future__ import annotations

from pathlib import Path

NAME = "figures"
HELP = "regenerate the paper's figures: CSV data and the PNG drawn from it"


def add_arguments(p) -> None:
    p.add_argument("--out", default="figures-out", help="output directory (default: figures-out)")
    p.add_argument("--only", action="append", default=None, metavar="NAME",
                   help="make only this figure (repeatable); see --list")
    p.add_argument("--list", action="store_true", help="list the figure names and exit")


def _summary(name: str, paths) -> str:
    """``fig6: 5808 rows (curves); wrote ...``: the size of each data table."""
    import pandas as pd

    sizes = []
    for path in paths:
        if path.suffix == ".csv":
            table = path.stem[len(name) + 1:] if path.stem.startswith(name + "_") else path.stem
            sizes.append(f"{len(pd.read_csv(path))} rows ({table})")
    return f"{name}: {', '.join(sizes) or 'no data table'}; wrote " + ", ".join(str(p) for p in paths)


def run(args) -> int:
    from tqdm import tqdm

    from .. import _validate as V
    from ..figures import FIGURES, figure_names, make_figure

    names = figure_names()
    if args.list:
        for n in names:
            print(f"{n:18s} {FIGURES[n].title}")
        return 0
    todo = names if not args.only else args.only
    for n in todo:
        if n not in names:
            raise ValueError(f"--only must be one of {', '.join(names)}; got {n!r}")
    out = V.output_dir("--out", args.out)
    for n in tqdm(todo, desc="figures", unit="fig", disable=None):
        paths = make_figure(n, out)
        tqdm.write(_summary(n, [Path(p) for p in paths]))
    if not args.only:
        _compile_fit_kernels()
    return 0


def _compile_fit_kernels() -> None:
    """Compile (or load) the march of every law ``jointdyn fit`` can fit, so that a first
    ``fit`` after ``figures`` (the README's first command) does not compile: the figures
    march most of these laws, but not ``segalman``. Instant when the cache holds them."""
    import numpy as np

    from ..drivers import march
    from ..identify.loops import LOOP_MODELS
    from ..laws import make_law

    for model in LOOP_MODELS:
        march(make_law(model, kt=1.0, mu=1.0, n_ref=1.0), np.array([0.0, 1.0]), np.ones(2))
