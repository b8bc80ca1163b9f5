"""The identification figure (ringdown_fit): its data and its files."""

import numpy as np
import pandas as pd

from jointdyn.figures import figure_names, make_figure


def test_ringdown_fit_data_and_files(tmp_path):
    assert "ringdown_fit" in figure_names()
    paths = make_figure("ringdown_fit", tmp_path)
    b = pd.read_csv(tmp_path / "ringdown_fit_backbone.csv")  # the data the picture was drawn from
    s = pd.read_csv(tmp_path / "ringdown_fit_signal.csv")
    e = pd.read_csv(tmp_path / "ringdown_fit_envelope.csv")
    assert len(b) >= 10 and len(s) > 10 * len(b) and len(e) > 0
    assert np.all(np.diff(b.amplitude_m) < 0)  # from the release down
    # the fitted model goes through the extracted points: within 1 % (the one-harmonic model in
    # macroslip, where the decay is far from harmonic)
    assert np.max(np.abs(b.omega_fit_rad_s / b.omega_rad_s - 1)) < 0.01
    # the model is fitted to the windows as `jointdyn fit --ringdown` does (fit_ringdown): over the
    # damping range it reports, its damping ratio (EPMC's) is within 5 % of the true model's EPMC
    # backbone, drawn beside it; the trimmed parts are in the data (the range's points, the times)
    ref = pd.read_csv(tmp_path / "ringdown_fit_epmc.csv")
    tr = pd.read_csv(tmp_path / "ringdown_fit_trimmed.csv")
    inside = b.damping_determined.astype(bool)
    assert 3 <= inside.sum() < len(b)
    D = np.interp(np.log(b.amplitude_m[inside]), np.log(ref.amplitude_m), ref.damping_ratio)
    assert np.max(np.abs(b.damping_fit[inside] / D - 1)) < 0.05
    assert np.all(b.damping_half_width[inside] <= 0.05) and np.all(b.damping_half_width[~inside] > 0.05)
    assert len(tr) == 2 and np.all(tr.end_s > tr.start_s) and tr.start_s.iloc[0] == s.t_s.iloc[0]
    assert {p.suffix for p in paths} >= {".png", ".csv"}
    assert all(p.stat().st_size > (100 if p.name == "ringdown_fit_trimmed.csv" else 1000) for p in paths)
