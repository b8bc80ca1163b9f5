"""``jointdyn figures``: one line per figure with the size of its data, and
an unusable --out refused before any figure is computed."""

from __future__ import annotations

import pandas as pd
import pytest

import jointdyn.figures
from jointdyn.cli import main


@pytest.fixture
def two_figures(monkeypatch):
    """Two stand-in figures: the real ones take minutes (they are tested in
    test_figures_*); this tests the command around them."""
    made = []

    def make_figure(name, out):
        made.append(name)
        rows = {"fig3": 6, "fig6": 5808}[name]
        csv = out / f"{name}_data.csv"
        pd.DataFrame({"a": range(rows)}).to_csv(csv, index=False)
        png = out / f"{name}.png"
        png.write_bytes(b"png")
        return [csv, png]

    monkeypatch.setattr(jointdyn.figures, "make_figure", make_figure)
    monkeypatch.setattr(jointdyn.figures, "figure_names", lambda: ["fig3", "fig6"])
    return made


def test_one_line_per_figure_with_its_size(two_figures, capsys, tmp_path):
    rc = main(["figures", "--out", str(tmp_path)])
    cap = capsys.readouterr()
    assert rc == 0 and two_figures == ["fig3", "fig6"]
    lines = cap.out.strip().splitlines()  # not a terminal: no progress bar, the lines still come
    assert len(lines) == 2
    assert lines[0].startswith("fig3: 6 rows (data); wrote ")
    assert lines[1].startswith("fig6: 5808 rows (data); wrote ")
    assert str(tmp_path / "fig6.png") in lines[1]


def test_out_refused_before_any_figure(two_figures, capsys, tmp_path):
    f = tmp_path / "file"
    f.write_text("keep")
    rc = main(["figures", "--out", str(f)])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "--out" in err
    assert two_figures == [] and f.read_text() == "keep"
