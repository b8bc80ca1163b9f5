"""What the pictures say: Greek letters and units in mathtext, legends that
cover no data, legend entries only for what is drawn, subtitles that parse.

The plotters run on small synthetic tables of the shape their ``compute``
writes (no solver runs here); ``save_figure`` is replaced by a function that
keeps the figure, drawn, for inspection.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from jointdyn.figures import _registry as R
from jointdyn.figures import dynamics as D
from jointdyn.figures import hb as H
from jointdyn.figures import joints as J
from jointdyn.figures import modes as M


@pytest.mark.parametrize("plain, math_", [
    ("gamma = w / w0", r"$\gamma$ = $\omega$ / $\omega_0$"),
    ("x (um)", r"x ($\mu$m)"),
    ("eta = 0.5, beta = 2, delta = 90 deg", r"$\eta$ = 0.5, $\beta$ = 2, $\delta$ = 90 deg"),
    ("theta = 45 deg, mu N0 / F1", r"$\theta$ = 45 deg, $\mu$ N0 / F1"),
    # whole words only, and mathtext already there stays as it is
    ("delta_deg, maximum, beta1, zetas", "delta_deg, maximum, beta1, zetas"),
    (r"$10^{-1}$ and eta", r"$10^{-1}$ and $\eta$"),
])
def test_math_text(plain, math_):
    assert R.math_text(plain) == math_


@pytest.fixture
def kept(monkeypatch):
    """Figures that the plotters would save, drawn (their texts laid out)."""
    figures = []

    def keep(fig, out_dir, name, dpi=130):
        R.use_math_text(fig)
        fig.canvas.draw()
        figures.append(fig)
        return []

    for module in (R, D, H, J, M):
        monkeypatch.setattr(module, "save_figure", keep)
    yield figures
    plt = R.pyplot()
    for fig in figures:
        plt.close(fig)


def _texts(fig) -> list[str]:
    from matplotlib.text import Text

    return [t.get_text() for t in fig.findobj(Text) if t.get_text()]


def _legends_clear_of_the_axes(fig):
    """No legend inside an axes, and every figure legend outside every axes."""
    assert all(ax.get_legend() is None for ax in fig.axes)
    assert fig.legends
    renderer = fig.canvas.get_renderer()
    for legend in fig.legends:
        box = legend.get_window_extent(renderer)
        for ax in fig.axes:
            assert not box.overlaps(ax.get_window_extent(renderer)), "a legend covers an axes"


def test_save_figure_writes_mathtext(tmp_path):
    plt = R.pyplot()
    fig, ax = plt.subplots()
    ax.set_xlabel("x (um)")
    ax.set_title("eta = 1.5")
    R.save_figure(fig, tmp_path, "t")
    assert ax.get_xlabel() == r"x ($\mu$m)" and ax.get_title() == r"$\eta$ = 1.5"
    assert (tmp_path / "t.png").is_file() and (tmp_path / "t.svg").is_file()


def _fig8_tables():
    rng = np.random.default_rng(0)
    loops, info = [], []
    for model, _, _ in D.FIG8_MODELS:
        for eta in D.FIG8_ETAS:
            for delta in D.FIG8_ENERGY_DELTAS:
                case = f"{model} {eta} {delta}"
                s = np.linspace(0, 2 * np.pi, 40, endpoint=False)
                loops.append(pd.DataFrame({"case": case, "x": 1e-4 * np.sin(s), "T": 40 * np.sin(s + 0.3),
                                           "code": (s > 5).astype(int) * 2}))
                info.append({"case": case, "model": model, "eta": eta, "delta_deg": delta, "status": "periodic",
                             "energy_contact_J": 1e-3 * (1 + rng.random())})
    return {"loops": pd.concat(loops, ignore_index=True), "cases": pd.DataFrame(info)}


def test_fig8_legend_below_the_panels_and_mathtext(kept):
    D._plot_fig8(_fig8_tables(), None)
    fig = kept[-1]
    _legends_clear_of_the_axes(fig)
    texts = "\n".join(_texts(fig))
    assert r"$\mu$m" in texts and r"$\delta$ = 90 deg" in texts and r"$\eta$ = 1.5" in texts
    assert " um)" not in texts and "eta =" not in texts.replace(r"\eta$ =", "")
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any("exact Iwan" in t for t in labels) and any("closed-form" in t for t in labels)


def test_modes_backbones_legend_below_the_panels(kept):
    rows = []
    for model, method in (("iwan", "epmc"), ("iwan", "qsma"), ("jenkins", "epmc"), (M.WEDGE_LABEL, "epmc")):
        a = np.logspace(-2, 2, 30)
        rows.append(pd.DataFrame({"model": model, "method": method, "amplitude_m": a * 1e-4, "amplitude_q": a,
                                  "gamma": 1.0 + 0.33 / (1 + a), "omega_rad_s": 200.0,
                                  "damping_ratio": 0.05 * a / (1 + a * a), "status": "complete"}))
    M._plot_modes_backbones({"backbones": pd.concat(rows, ignore_index=True)}, None)
    fig = kept[-1]
    _legends_clear_of_the_axes(fig)
    assert r"natural frequency $\omega$ / $\omega_0$" in _texts(fig)


def test_blade_damper_legend_below_the_panels(kept):
    rows = []
    for p in J.BLADE_CURVES:
        for d in ("up", "down"):
            g = np.linspace(0.8, 1.3, 30)
            status = np.where(g > 1.25, "not-settled", "periodic")
            rows.append(pd.DataFrame({"preload_N": p, "direction": d, "gamma": g,
                                      "amplitude_m": 1e-3 / (1 + 50 * (g - 1) ** 2), "status": status}))
    design = pd.DataFrame({"preload_N": J.BLADE_PRELOADS, "peak_m": np.linspace(1.5e-3, 0.8e-3, len(J.BLADE_PRELOADS))})
    limits = pd.DataFrame({"limit": ["no damper", "damper stuck"], "peak_m": [2.75e-3, 2.5e-3],
                           "gamma_peak": [0.772, 1.091]})
    J._plot_blade_damper({"curves": pd.concat(rows, ignore_index=True), "design": design, "limits": limits}, None)
    fig = kept[-1]
    _legends_clear_of_the_axes(fig)
    assert r"$\gamma$ = $\omega$ / $\omega_0$" in _texts(fig)


def _legend_labels(fig) -> list[str]:
    return [t.get_text() for legend in fig.legends for t in legend.get_texts()]


def test_fig6_legend_names_only_the_statuses_that_occur():
    plt = R.pyplot()
    for statuses, expected in (({"periodic"}, set()), ({"periodic", "unbounded"}, {"unbounded (rug)"}),
                               ({"not-settled", "unbounded"}, {"unbounded (rug)", "not settled (rug)"})):
        fig, ax = plt.subplots()
        ax.plot([1, 2], [1, 2], label="beta = 1")
        D._fig6_legend(fig, ax, statuses)
        assert {t for t in _legend_labels(fig) if "rug" in t} == expected
        plt.close(fig)


def test_fig6_hb_legend_names_only_what_is_drawn():
    plt = R.pyplot()
    stable = pd.DataFrame({"stable": [1, 1, 1], "fold": [0, 0, 0]})
    unstable = pd.DataFrame({"stable": [1, 0, 1], "fold": [0, 1, 0]})
    td = pd.DataFrame({"direction": ["up", "down"], "status_name": ["periodic", "not-settled"]})
    for hb, t, expected in ((stable, None, set()),
                            (unstable, td, {"HB unstable (Hill)", "HB fold", "time domain, sweep up (periodic points)"})):
        fig = plt.figure()
        H._hb_legend(fig, [1.0, 2.0], {}, hb, t)
        assert set(_legend_labels(fig)) - {"beta = 1", "beta = 2"} == expected
        plt.close(fig)


def test_fig7_subtitle_reads():
    jump = D._drop_text(1.01, 0.0, 5.9)
    assert jump == "T at A, where opening starts: 1.01 N, lost with no travel (a jump)"
    assert D._drop_text(1.01, 0.04, 5.9).endswith("lost within 4 % of the amplitude")
    assert D._drop_text(0.0535, 0.0, 6.3).endswith("0.0535 N, next to nothing: no force jump")
    assert D._drop_text(math.nan, math.nan, 6.3) == "the contact does not open"
    assert "over 0 of" not in jump
