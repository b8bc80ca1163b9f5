"""``jointdyn figures``: regenerate the paper's figures (data + PNG)."""

from __future__ import annotations

from pathlib import Path

NAME = "figures"
HELP = "regenerate the paper's figures: CSV data and the PNG drawn from it"


def add_arguments(p) -> None:
    p.add_argument("--out", default="figures-out", help="output directory (default: figures-out)")
    p.add_argument("--only", action="append", default=None, metavar="NAME",
                   help="make only this figure (repeatable); see --list")
    p.add_argument("--list", action="store_true", help="list the figure names and exit")


def run(args) -> int:
    from tqdm import tqdm

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
    out = Path(args.out)
    for n in tqdm(todo, desc="figures", unit="fig", disable=None):
        paths = make_figure(n, out)
        tqdm.write(f"{n}: " + ", ".join(str(p) for p in paths))
    return 0
