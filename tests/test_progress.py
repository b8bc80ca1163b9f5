"""Progress that means something: HB and EPMC bars fill over the continued
parameter's range (not against max_points), and the first run after
installing says once on stderr that it compiles."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from jointdyn import continuation as C
from jointdyn._jit import ANNOUNCE_ENV, COMPILING_NOTE


def test_fraction_is_the_farthest_share_of_the_range_reached():
    bar = C.ParameterProgress(2.0, 1.0, "x", progress=False)  # a range run downwards
    for lam, done in ((2.0, 0), (1.75, 250), (1.9, 250), (0.5, 1000)):  # a fold going back does not undo
        bar.reached(lam)
        assert bar.done == done
    assert C.ParameterProgress(1.0, 1.0, "x", progress=False).fraction(1.0) == 0.0


def test_continuation_fills_the_bar_over_the_range():
    """y = lam^2 from lam 0 to 3: the bar ends full, however many points the step control took."""
    def residual(y, lam):
        return np.array([y[0] - lam * lam]), np.eye(1), np.array([-2.0 * lam])

    with C.ParameterProgress(0.0, 3.0, "test", progress=True, name="lam") as bar:
        res = C.continuation(residual, np.zeros(1), 0.0, 3.0, progress=bar, max_points=2000)
        assert res.status == "complete" and bar.done == bar.STEPS
        assert bar.bar.n == bar.STEPS and bar.bar.postfix == "lam = 3"
    assert res.lam.size < 2000


@pytest.fixture
def recorded(monkeypatch):
    """Every ParameterProgress made by hb.branch and modes.epmc."""
    import importlib

    frc = importlib.import_module("jointdyn.hb.branch")
    epmc = importlib.import_module("jointdyn.modes.epmc")

    bars = []

    class Recording(C.ParameterProgress):
        def __init__(self, *a, **k):
            super().__init__(*a, **k)
            bars.append(self)

    monkeypatch.setattr(frc, "ParameterProgress", Recording)
    monkeypatch.setattr(epmc, "ParameterProgress", Recording)
    return bars


def test_hb_bar_over_gamma(recorded):
    import jointdyn as jd

    br = jd.frc_hb(jd.System.paper_damper(eta=0.5, beta=2.0), 0.6, 1.8, progress=True)
    assert br.attrs["status"] == "complete"
    first = recorded[0]
    assert first.name == "gamma" and first.done == first.STEPS
    assert first.start * first.scale == pytest.approx(0.6) and (first.start + first.span) * first.scale == \
        pytest.approx(1.8)


def test_epmc_bar_over_log_amplitude(recorded):
    import jointdyn as jd
    from jointdyn.modes import epmc

    b = epmc(jd.System.paper_damper(eta=0.0), (1e-6, 1e-4), harmonics=3, samples=32, progress=True)
    assert b.status.ok
    (bar,) = recorded
    assert bar.name == "log10(a / m)" and bar.done == bar.STEPS
    assert bar.start == pytest.approx(-6.0) and bar.span == pytest.approx(2.0)


_KERNELS = """\
from jointdyn._jit import jit


@jit
def twice(x):
    return 2.0 * x


@jit
def thrice(x):
    return 3.0 * x
"""


def _run(tmp_path, cache: str, announce: bool):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / cache), PYTHONPATH=str(tmp_path))
    env.pop(ANNOUNCE_ENV, None)
    if announce:
        env[ANNOUNCE_ENV] = "1"
    code = "import kernels_for_the_note as k; print(k.twice(1.0) + k.thrice(1.0))"
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return proc


def test_compiling_note_once_on_a_cold_cache_only(tmp_path):
    (tmp_path / "kernels_for_the_note.py").write_text(textwrap.dedent(_KERNELS))
    quiet = _run(tmp_path, "api", announce=False)  # a Python caller: nothing on its stderr
    assert quiet.stdout.strip() == "5.0" and COMPILING_NOTE not in quiet.stderr
    cold = _run(tmp_path, "cli", announce=True)  # two kernels compiled, one note
    assert cold.stdout.strip() == "5.0" and cold.stderr.count(COMPILING_NOTE) == 1
    warm = _run(tmp_path, "cli", announce=True)  # loaded from the cache: no note
    assert warm.stdout.strip() == "5.0" and COMPILING_NOTE not in warm.stderr


def test_the_jointdyn_process_asks_for_the_note(monkeypatch):
    from jointdyn import cli

    monkeypatch.delenv(ANNOUNCE_ENV, raising=False)
    monkeypatch.setattr(cli, "main", lambda argv=None: 0)
    assert cli.console() == 0 and os.environ[ANNOUNCE_ENV] == "1"


def test_a_stage_writes_plain_lines_where_stderr_is_not_a_terminal(capsys, monkeypatch):
    """Plain lines (the items done of the total, the time left, a last line) once the stage has taken
    QUIET_S seconds (0 here); nothing with progress=False; a short stage says nothing."""
    monkeypatch.setattr(C.StageProgress, "QUIET_S", 0.0)
    with C.stage_progress(8, "stability (arnoldi)", None, unit="point") as bar:
        for _ in range(8):
            bar.update(1)
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith("stability (arnoldi): 2/8 points, ") and "s left" in err[0]
    assert len(err) == C.StageProgress.LINES and err[-1].startswith("stability (arnoldi): 8/8 points done in ")
    with C.stage_progress(8, "x", False) as bar:
        bar.update(8)
    monkeypatch.setattr(C.StageProgress, "QUIET_S", 1e9)
    with C.stage_progress(8, "x", True) as bar:
        bar.update(8)
    C.stage_note("HB level 1/6: H = 7, Ns = 128", False)
    assert capsys.readouterr().err == ""
    C.stage_note("HB level 1/6: H = 7, Ns = 128")
    assert capsys.readouterr().err == "HB level 1/6: H = 7, Ns = 128\n"


def test_each_level_of_an_automatic_choice_says_which_it_is(capsys):
    from jointdyn.hb import HBOptions
    from jointdyn.hb.discretisation import level_number

    bounds = HBOptions()
    from jointdyn.hb.levels import Discretisation, Level

    d = Discretisation.of("auto", "auto")
    h0, s0 = d.first
    # raises of H (H -> 2H + 1) and of Ns (doubling) within their bounds, counted by hand from the bounds
    h_levels = sum(1 for h in (2 * h0 + 1, 4 * h0 + 3, 8 * h0 + 7) if h <= bounds.auto_max_harmonics)
    s_levels = sum(1 for k in range(1, 12) if s0 * 2 ** k <= bounds.auto_max_samples)
    most = 1 + h_levels + s_levels
    assert level_number(d.first, d) == (1, most)
    assert level_number(Level(2 * h0 + 1, 2 * s0), d) == (3, most)
    assert level_number(Level(h0, 2 * s0), Discretisation.of(h0, "auto")) == (2, 1 + s_levels)
