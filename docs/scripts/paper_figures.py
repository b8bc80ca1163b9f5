"""Pictures and tables of the paper-figure pages (docs/paper/*.md).

Usage::

    PYTHONPATH=src python docs/scripts/paper_figures.py            # compute every figure (minutes)
    PYTHONPATH=src python docs/scripts/paper_figures.py --from DIR # reuse `jointdyn figures --out DIR`

Runs the figure registry (the same code as ``jointdyn figures``), copies each
PNG into ``docs/img/`` and rewrites the tables of the paper-figure pages
between their ``<!-- table:PAGE:NAME:begin -->`` / ``<!-- table:PAGE:NAME:end -->``
markers from the CSV files the pictures were drawn from. Nothing on those
pages that is a number of ours is typed by hand.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

DOCS = Path(__file__).resolve().parents[1]
IMG = DOCS / "img"
PAPER = DOCS / "paper"


def _md(df: pd.DataFrame) -> str:
    """Markdown table of a small frame (strings as given, floats with 4 significant digits)."""
    cols = list(df.columns)
    out = ["| " + " | ".join(cols) + " |", "|" + "|".join("---:" for _ in cols) + "|"]
    for _, row in df.iterrows():
        cells = [f"{v:.4g}" if isinstance(v, (float, np.floating)) else str(v) for v in row]
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def table_fig2(d: Path) -> str:
    m = pd.read_csv(d / "fig2_metrics.csv")
    kt, fy = 1.0e5, 10.0
    rows = []
    for _, r in m.iterrows():
        A = r.amplitude_m
        closed = kt**2 * A**3 / (3 * fy) if A <= 2 * fy / kt else 4 * fy * A - 16 * fy**2 / (3 * kt)
        rows.append({"A (mm)": A * 1e3, "energy per cycle (mJ)": r.energy_J * 1e3,
                     "closed form (mJ)": closed * 1e3, "macroslip fraction of the cycle": r.macroslip_fraction})
    return _md(pd.DataFrame(rows))


def table_loops(d: Path, name: str) -> str:
    m = pd.read_csv(d / f"{name}_metrics.csv")
    cols = {"eta": "eta", "energy_J": "energy per cycle (mJ)", "force_max_N": "max T (N)",
            "force_min_N": "min T (N)", "stick_slip_fraction": "stick-slip", "macroslip_fraction": "macroslip",
            "separation_fraction": "separation"}
    t = m[list(cols)].rename(columns=cols)
    t["energy per cycle (mJ)"] *= 1e3
    return _md(t)


def table_fig6(d: Path) -> str:
    df = pd.read_csv(d / "fig6_curves.csv")
    rows = []
    for (eta, beta), g in df[df.direction == "up"].groupby(["eta", "beta"]):
        ok = g[g.status_name == "periodic"]
        i = ok.amplitude_q.idxmax()
        rows.append({"eta": eta, "beta": beta, "peak gamma (sweep up)": ok.gamma[i],
                     "peak amplitude q": ok.amplitude_q[i],
                     "points without steady state (up, down)": int((df[(df.eta == eta) & (df.beta == beta)]
                                                                    .status_name != "periodic").sum())})
    return _md(pd.DataFrame(rows))


def table_fig7(d: Path) -> str:
    c = pd.read_csv(d / "fig7_cases.csv")
    t = c[["case", "delta_deg", "status", "drop_T_N", "drop_dx_over_amp", "energy_contact_J"]].copy()
    t.columns = ["case", "delta (deg)", "status", "load when opening starts (N)",
                 "travel while losing it / amplitude", "energy per cycle (J)"]
    return _md(t)


def table_fig8(d: Path) -> str:
    c = pd.read_csv(d / "fig8_cases.csv")
    c = c[c.status == "periodic"]
    t = c.pivot_table(index="delta_deg", columns=["eta", "model"], values="energy_contact_J") * 1e3
    t.columns = [f"E (mJ), eta {eta:g}, {model}" for eta, model in t.columns]
    t = t.reset_index().rename(columns={"delta_deg": "delta (deg)"})
    return _md(t)


TABLES = {
    ("fig2", "energy"): table_fig2,
    ("fig3", "metrics"): lambda d: table_loops(d, "fig3"),
    ("fig4", "metrics"): lambda d: table_loops(d, "fig4"),
    ("fig6", "peaks"): table_fig6,
    ("fig7", "cases"): table_fig7,
    ("fig8", "energy"): table_fig8,
}


def replace_block(text: str, name: str, table: str) -> str:
    begin, end = f"<!-- table:{name}:begin -->", f"<!-- table:{name}:end -->"
    i, j = text.index(begin) + len(begin), text.index(end)
    return text[:i] + "\n" + table + "\n" + text[j:]


def write_pages(data: Path) -> None:
    for (page, name), make in TABLES.items():
        path = PAPER / f"{page}.md"
        path.write_text(replace_block(path.read_text(), f"{page}:{name}", make(data)))
    for png in data.glob("*.png"):
        shutil.copyfile(png, IMG / png.name)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--from", dest="src", type=Path, help="output folder of `jointdyn figures` to reuse")
    args = ap.parse_args(argv)
    if args.src is not None:
        write_pages(args.src)
        return 0
    from jointdyn.figures import figure_names, make_figure

    with tempfile.TemporaryDirectory() as tmp:
        for name in figure_names():
            print(name, file=sys.stderr)
            make_figure(name, tmp)
        write_pages(Path(tmp))
    return 0


if __name__ == "__main__":
    sys.exit(main())
