"""The solvers' options objects: each refuses a bad value naming the field and its allowed range, and its
defaults are the values its docstring documents (parsed from the docstring, so that a changed default
without its documentation fails)."""

from __future__ import annotations

import dataclasses
import inspect
import re

import pytest

from jointdyn.dynamics import MarchOptions, SteadyStateOptions
from jointdyn.hb import HBOptions
from jointdyn.modes import EPMCOptions, QSMAOptions

#: one bad value per field of each options class, and a word of the message that says the allowed range
BAD = {
    HBOptions: {"dense_max_unknowns": (-1, ">= 0"), "block_preconditioner": (1, "True or False"),
                "auto_early_drop": (0.0, "(0.0, 1.0]"), "auto_max_harmonics": (0, ">= 1"),
                "auto_max_samples": (3, ">= 4"), "start_max_iter": (0, ">= 1"), "solve_max_iter": (2.5, ">= 1"),
                "homotopy_start": (1.0, "(0.0, 1.0)"), "unbounded_q": (0.0, "(0, inf)"),
                "unbounded_fail_fraction": (1.5, "(0.0, 1.0]"), "saturation_q": (-1.0, "(0, inf)"),
                "saturation_slip_fraction": (0.0, "(0.0, 1.0]"), "turning_band": (0.0, "(0, inf)"),
                "turning_band_log_q": (float("nan"), "finite"), "fold_window": (0, ">= 1"),
                "peak_prominence": (1.0, "[0.0, 1.0)"), "jacobian_budget_bytes": (0, ">= 1"),
                "max_gamma_step": (-0.01, "(0, inf)"), "condense_min_dofs": (0, ">= 1"),
                "condense_max_fraction": (0.0, "(0.0, 1.0]"), "condense_relative": (1, "True or False")},
    EPMCOptions: {"ds_start": (0.0, "(0, inf)"), "ds_max": (-1.0, "(0, inf)"), "tol": (0.0, "(0, inf)"),
                  "start_max_iter": (0, ">= 1"), "auto_check_points": (0, ">= 1")},
    QSMAOptions: {"steps_per_decade": (0, ">= 1"), "decades_below": (0, ">= 1"), "substeps": (0, ">= 1"),
                  "tol": (0.0, "(0, inf)"), "max_iter": (0, ">= 1")},
    MarchOptions: {"steps_per_period": (3, ">= 4"), "max_omega_h": (3.0, "(0.0, 2.8284271247461903]"),
                   "spring_omega_h": (1.5, "(0.0, 1.0]"), "max_splits": (-1, ">= 0"),
                   "event_merge": (0.5, "[0.0, 0.5)"), "recontact_alpha": (0.0, "(0.0, 1.0)"),
                   "blowup_factor": (1.0, "(1.0, inf)")},
    SteadyStateOptions: {"march": (256, "MarchOptions"), "linear_iters": (0, ">= 1"),
                         "linear_rtol": (0.0, "(0, inf)"), "amp_rtol": (0.0, "(0, inf)"),
                         "energy_rtol": (-1e-3, "(0, inf)"), "balance_rtol": (0.0, "(0, inf)"),
                         "check_periods": (1, ">= 2"), "max_multiple": (0, ">= 1"),
                         "detect_multiple": (3, ">= max_multiple = 4"), "multiple_decay": (0.0, "(0.0, 1.0]"),
                         "stall_periods": (1, ">= 2"), "stall_ratio": (1.5, "(0.0, 1.0]"),
                         "max_periods": (0, ">= 1"), "chunk": (0, ">= 1"), "shoot_after": (0.0, "(0, inf)"),
                         "shoot_maxit": (0, ">= 1"), "shoot_maxstep": (0.0, "(0, inf)"),
                         "shoot_halvings": (0, ">= 1"), "shoot_clean_state": ("yes", "True or False"),
                         "max_shots": (-1, ">= 0"), "shoot_fd": (0.0, "(0, inf)"),
                         "floquet_tol": (0.0, "(0, inf)"), "growth_periods": (1, ">= 2"),
                         "growth_ratio": (0.0, "(0.0, 1.0]"), "unbounded_q": (0.0, "(0, inf)")},
}

_NUMBER = re.compile(r"(True|False|[-+]?\d+(?:\.\d*)?(?:e[-+]?\d+)?(?:\*\*\d+)?)")


def documented_defaults(cls) -> dict:
    """Field -> the default its docstring's Attributes entry states (``default V``, or ``defaults V and W``
    for an entry of two fields)."""
    doc = inspect.cleandoc(cls.__doc__).split("Attributes\n----------\n", 1)[1]
    out = {}
    for entry in re.split(r"\n(?=\w)", doc):
        head, _, body = entry.strip("\n").partition(" : ")
        names = [n.strip() for n in head.split(",")]
        said = re.search(r"\(defaults? (``\w+\(\)``|[^;)]*)", body.replace("\n", " "))
        if not said:
            continue
        if said.group(1).startswith("``"):  # an options object within another: its defaults, by class name
            out[names[0]] = said.group(1).strip("`")
            continue
        values = [eval(v) for v in _NUMBER.findall(said.group(1))]  # noqa: S307 (literals of our docstring)
        for name, value in zip(names, values):
            out[name] = value
    return out


@pytest.mark.parametrize("cls", list(BAD), ids=lambda c: c.__name__)
def test_defaults_are_the_documented_values(cls):
    fields = {f.name: f.default for f in dataclasses.fields(cls)}
    documented = documented_defaults(cls)
    assert set(documented) == set(fields), f"fields without a documented default: {set(fields) - set(documented)}"
    for name, value in fields.items():
        if dataclasses.is_dataclass(value):  # an options object within another: documented by class name
            assert documented[name] == f"{type(value).__name__}()" and value == type(value)(), name
            continue
        assert documented[name] == value and isinstance(documented[name], bool) == isinstance(value, bool), name
    made = cls()
    assert {name: getattr(made, name) for name in fields} == fields


def test_documented_defaults_parser_reads_what_it_is_shown():
    # the parser on a docstring of the same form: a changed default fails the test above
    class Shown:
        """X.

        Attributes
        ----------
        a : int
            Something (default 3; >= 1).
        b, c : float
            Two things (defaults 1e-3 and 2**4).
        d : bool
            A flag (default True).
        e : float
            Undocumented.
        """

    assert documented_defaults(Shown) == {"a": 3, "b": 1e-3, "c": 16, "d": True}


@pytest.mark.parametrize("cls,field,value,allowed", [(c, f, v, a) for c, bad in BAD.items()
                                                     for f, (v, a) in bad.items()],
                         ids=lambda x: getattr(x, "__name__", None) or str(x))
def test_a_bad_value_is_refused_naming_the_field_and_the_range(cls, field, value, allowed):
    with pytest.raises(ValueError) as err:
        cls(**{field: value})
    msg = str(err.value)
    assert msg.startswith(field + " ") and allowed in msg, msg


def test_every_field_has_a_bad_value_here():
    for cls, bad in BAD.items():
        assert set(bad) == {f.name for f in dataclasses.fields(cls)}, cls.__name__


def test_options_are_frozen_and_refused_in_the_wrong_place():
    from jointdyn.hb import frc_hb
    from jointdyn.modes import qsma
    from jointdyn.systems import System

    with pytest.raises(dataclasses.FrozenInstanceError):
        HBOptions().fold_window = 2
    with pytest.raises(ValueError, match="hb_options must be an HBOptions"):
        frc_hb(System.paper_damper(), 0.6, 1.8, hb_options=EPMCOptions())
    with pytest.raises(ValueError, match="options must be a QSMAOptions"):
        qsma(System.paper_damper(eta=0.0), options=HBOptions())
    with pytest.raises(ValueError, match="ds_start must be in"):
        EPMCOptions(ds_start=0.1, ds_max=0.05)


def test_steady_state_takes_its_numbers_from_its_options():
    """The options object and the keyword arguments of steady_state are the same numbers: bit for bit the
    same steady state either way; a keyword argument replaces the option's field."""
    from jointdyn.dynamics import steady_state
    from jointdyn.systems import System

    s = System.paper_damper(eta=0.5, beta=2.0)
    default = steady_state(s, 1.1, keep_loop=False)
    by_kw = steady_state(s, 1.1, max_periods=8, keep_loop=False)
    by_options = steady_state(s, 1.1, options=SteadyStateOptions(max_periods=8), keep_loop=False)
    both = steady_state(s, 1.1, max_periods=8, options=SteadyStateOptions(max_periods=800), keep_loop=False)
    assert default.status.ok and default.periods > 8  # the default settles later than the cap asked here
    assert not by_kw.status.ok and by_kw.periods == 8
    for other in (by_options, both):
        assert (other.status, other.periods, other.steps, other.last_amplitude_m) == \
            (by_kw.status, by_kw.periods, by_kw.steps, by_kw.last_amplitude_m)
    with pytest.raises(ValueError, match="options must be a SteadyStateOptions"):
        steady_state(s, 1.1, options=HBOptions())


def test_a_sweep_passes_its_steady_options_to_every_point(tmp_path):
    """``SweepOptions.steady`` reaches every point's steady state, enters the line's checkpoint key only when
    given (the key of a line with the defaults is the one it always was), and is refused when not one."""
    from jointdyn.dynamics import steady_state
    from jointdyn.sweeps import SweepOptions, frc_sweep
    from jointdyn.sweeps._family import LineSpec
    from jointdyn.systems import System

    s = System.paper_damper(eta=0.5, beta=2.0)
    capped = SteadyStateOptions(max_periods=8)
    ds = frc_sweep(s, [1.1], directions="up", n_workers=1, progress=False,
                   options=SweepOptions(steady=capped))
    alone = steady_state(s, 1.1, options=capped, keep_loop=True)
    assert not alone.status.ok and int(ds.status.values.ravel()[0]) == alone.status.code
    assert ds.attrs["steady_options"] == repr(capped)
    plain = LineSpec(label="a", system="k", direction="up", gammas=(1.0,))
    assert plain.to_json() == LineSpec(label="a", system="k", direction="up", gammas=(1.0,), steady=None).to_json()
    assert "steady" not in plain.to_json()
    assert LineSpec(label="a", system="k", direction="up", gammas=(1.0,), steady=capped).key != plain.key
    with pytest.raises(ValueError, match="steady must be a SteadyStateOptions"):
        SweepOptions(steady=HBOptions())


def test_the_march_takes_its_numbers_from_its_options():
    """Each field of MarchOptions reaches the march it is given to (closed forms of the step grid, the
    blow-up caps, the re-contact load, the splits), and integrate's and steady_state's steps_per_period
    keyword is the same number as the options' field: bit for bit the same run either way."""
    import math

    import numpy as np

    from jointdyn.dynamics import check_period_steps, integrate, steady_state
    from jointdyn.dynamics._model import make_model, pack_system, recontact_load
    from jointdyn.systems import System

    s = System.paper_damper(eta=0.5, beta=2.0)
    w = 1.1 * s.w0
    pack = pack_system(s)
    for wh in (0.5, 0.05):
        m = make_model(s, w, MarchOptions(steps_per_period=8, max_omega_h=wh, spring_omega_h=wh))
        assert m.J == max(8, math.ceil(2 * math.pi * pack.w_max / (w * wh)))
    base, tight = make_model(s, w, MarchOptions()), make_model(s, w, MarchOptions(blowup_factor=1e4))
    assert tight.xcap0 == pytest.approx(1e-4 * base.xcap0, rel=1e-14)
    assert make_model(s, w, MarchOptions(max_splits=2)).max_split == 2
    assert make_model(s, w, MarchOptions(max_splits=2), events=False).max_split == 0
    spp16 = MarchOptions(steps_per_period=16, max_omega_h=0.05, spring_omega_h=0.05)
    need = math.ceil(2 * math.pi * pack.w_max / (w * 0.05))
    assert check_period_steps(s, w, march=spp16) == need > 16  # the sweeps' and the CLI's check, same march
    assert check_period_steps(s, w, 4 * need, march=spp16) == 4 * need  # the keyword replaces the field
    n0 = s.contacts[0].n0
    assert recontact_load(pack.kin, 0, MarchOptions(recontact_alpha=1e-6)) == 1e-6 * n0
    a = integrate(s, 1.1, periods=2, steps_per_period=512)
    b = integrate(s, 1.1, periods=2, options=MarchOptions(steps_per_period=512))
    assert np.array_equal(a.t, b.t) and np.array_equal(a.x, b.x) and np.array_equal(a.T, b.T)
    c = integrate(s, 1.1, periods=2, steps_per_period=512, options=MarchOptions(steps_per_period=64))
    assert np.array_equal(a.x, c.x)  # the keyword replaces the field
    by_kw = steady_state(s, 1.1, steps_per_period=512, max_periods=8, keep_loop=False)
    by_options = steady_state(s, 1.1, keep_loop=False, options=SteadyStateOptions(
        max_periods=8, march=MarchOptions(steps_per_period=512)))
    assert (by_kw.steps, by_kw.last_amplitude_m) == (by_options.steps, by_options.last_amplitude_m)
    with pytest.raises(ValueError, match="options must be a MarchOptions"):
        integrate(s, 1.1, options=SteadyStateOptions())
    with pytest.raises(ValueError, match="steps_per_period must be an integer >= 4"):
        steady_state(s, 1.1, steps_per_period=2)
