"""Bad input to the contact laws and to march: ValueError naming the parameter.

Every registered law is checked (its common parameters, its declared law
parameters, overflowing scales, user-supplied states); a few law-specific
rules (Jenkins is one element, the Iwan state's integer fields) follow.
"""

import math

import numpy as np
import pytest

from law_cases import registry_laws

from jointdyn import DiscreteIwan, Iwan, IwanClosedForm, Jenkins, make_law, march
from jointdyn.laws import canonical_law_params, law_names, law_parameters

GOOD = dict(kt=1e5, mu=0.1, n_ref=100.0)
BAD_VALUES = {
    "kt": [0.0, -1.0, math.nan, math.inf, "abc"],
    "mu": [-0.1, math.nan, math.inf, -math.inf],
    "n_ref": [0.0, -5.0, math.nan, math.inf],
}
#: law params -> every registered law (and parameter variant) built at GOOD
LAWS = {case: law for case, _, law in registry_laws(**GOOD)}


@pytest.mark.parametrize("name", law_names())
@pytest.mark.parametrize("param,value", [(k, v) for k, vs in BAD_VALUES.items() for v in vs])
def test_bad_common_parameters(name, param, value):
    with pytest.raises(ValueError, match=param):
        make_law(name, **{**GOOD, param: value})


@pytest.mark.parametrize("cls", [Iwan, IwanClosedForm, DiscreteIwan, Jenkins])
@pytest.mark.parametrize("param,value", [("kt", 0.0), ("mu", -1.0), ("n_ref", math.nan)])
def test_bad_common_parameters_classes(cls, param, value):
    with pytest.raises(ValueError, match=param):
        cls(**{**GOOD, param: value})


def _bad_law_values(p):
    """Values outside a declared law parameter's range or kind."""
    if p.kind == "choice":
        return ["no-such-choice", 3, None]
    bad = [math.nan, math.inf, "x", None, True]
    if math.isfinite(p.low):
        bad.append(p.low - 1)
    if math.isfinite(p.high):
        bad.append(p.high + 1)
    if p.kind == "int":
        bad.append(p.low + 0.5 if math.isfinite(p.low) else 0.5)
    return bad


_LAW_PARAM_CASES = [
    pytest.param(name, p.name, v, id=f"{name}-{p.name}-{v!r}")
    for name in law_names()
    for p in law_parameters(name)
    for v in _bad_law_values(p)
]


@pytest.mark.parametrize("name,param,value", _LAW_PARAM_CASES)
def test_bad_law_parameters(name, param, value):
    """A declared law parameter out of its range: ValueError naming it (from
    make_law and from the canonical tuple used by sweeps)."""
    with pytest.raises(ValueError, match=f"{param} must"):
        make_law(name, **GOOD, **{param: value})
    with pytest.raises(ValueError, match=f"{param} must"):
        canonical_law_params(name, {param: value})


@pytest.mark.parametrize("name", law_names())
def test_unknown_law_parameter_is_refused(name):
    """make_law refuses a parameter the law does not have and lists the allowed ones."""
    allowed = [p.name for p in law_parameters(name)]
    with pytest.raises(ValueError, match="no_such_parameter is not a parameter") as err:
        make_law(name, **GOOD, no_such_parameter=1)
    for a in allowed:
        assert a in str(err.value)
    if "n" not in allowed:  # n of discrete is not silently ignored by the others
        with pytest.raises(ValueError, match="n is not a parameter"):
            make_law(name, **GOOD, n=1000)


@pytest.mark.parametrize("name", law_names())
def test_declared_parameters_listed_and_accepted(name):
    """law_parameters describes every law-specific parameter (name, default,
    units, help, allowed range) and make_law accepts each at its default and
    as a string (command lines)."""
    for p in law_parameters(name):
        assert p.name and p.units and p.help and p.allowed()
        law = make_law(name, **GOOD, **{p.name: p.default})
        assert getattr(law, p.name) == p.default
        assert getattr(make_law(name, **GOOD, **{p.name: str(p.default)}), p.name) == p.default
    assert canonical_law_params(name) == tuple(sorted((p.name, p.default) for p in law_parameters(name)))


@pytest.mark.parametrize("name", law_names())
@pytest.mark.parametrize(
    "kw,param",
    [
        (dict(kt=1e5, mu=1e300, n_ref=1e10), "mu"),  # fy = mu n_ref overflows
        (dict(kt=1e5, mu=1e308, n_ref=100.0), "mu"),
        (dict(kt=1e5, mu=1e-320, n_ref=1.0), "mu"),  # kt / fy overflows
        (dict(kt=1e-300, mu=1.0, n_ref=1e10), "kt"),  # fy / kt overflows
        (dict(kt=1e5, mu=0.1, n_ref=1e-310), "n_ref"),  # 1 / n_ref overflows
    ],
)
def test_overflowing_scales_are_refused(name, kw, param):
    """Parameters whose derived scales are not finite: ValueError naming the
    parameter and its allowed range."""
    with pytest.raises(ValueError, match=rf"{param} must be (0 or )?in \["):
        make_law(name, **kw)


def test_overflow_of_issue_12():
    with pytest.raises(ValueError, match=r"mu must be in \[0, "):
        Iwan(kt=1e5, mu=1e300, n_ref=1e10)


@pytest.mark.parametrize("name", law_names())
def test_scales_finite_at_the_limits(name):
    """Just inside the limits every scale a solver uses is finite."""
    law = make_law(name, kt=1e5, mu=1e300, n_ref=1.0)
    for v in (law.fy, law.kt / law.fy, law.displacement_scale, law.x_slip):
        assert math.isfinite(v) and v > 0.0


def test_jenkins_is_one_element():
    with pytest.raises(ValueError, match="n must be 1"):
        Jenkins(**GOOD, n=2)


def test_unknown_model_name():
    with pytest.raises(ValueError, match="model"):
        make_law("coulomb", **GOOD)


def test_good_parameters_accepted():
    for name in law_names():
        assert make_law(name, **GOOD).fy == pytest.approx(10.0)
    assert make_law("discrete", **GOOD, n=10).n == 10
    assert make_law("iwan-paper", **GOOD).memory == "last"
    assert make_law("iwan-closed", **GOOD).memory == "full"
    assert isinstance(make_law("iwan", **GOOD), Iwan)
    assert Iwan(kt=1e5, mu=0.0, n_ref=100.0).fy == 0.0  # mu = 0 is allowed


#: the closed form, whose state has integer fields (stack depth, base code, direction)
LAW = IwanClosedForm(**GOOD)


def test_march_different_lengths():
    with pytest.raises(ValueError, match=r"x=5, N=4"):
        march(LAW, np.zeros(5), np.ones(4))


@pytest.mark.parametrize("which", ["x", "N"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_march_non_finite(which, bad):
    x = np.zeros(5)
    N = np.full(5, 100.0)
    (x if which == "x" else N)[2] = bad
    with pytest.raises(ValueError, match=f"{which} must be finite"):
        march(LAW, x, N)


@pytest.mark.parametrize("which", ["x", "N"])
def test_march_empty_or_2d(which):
    good = np.zeros(3)
    for bad in (np.zeros(0), np.zeros((3, 2))):
        args = (bad, good) if which == "x" else (good, bad)
        with pytest.raises(ValueError, match=which):
            march(LAW, *args)


@pytest.mark.parametrize("law", ["iwan", None, 3.0, Iwan])
def test_march_law_not_a_law(law):
    with pytest.raises(ValueError, match="law must be a ContactLaw"):
        march(law, [0.0, 1e-4], [100.0, 100.0])


@pytest.mark.parametrize("case", sorted(LAWS))
def test_march_bad_state(case):
    """A state of the wrong shape or type, or with NaN/inf in it, is refused
    before any compiled call (a NaN Iwan state used to crash the process)."""
    law = LAWS[case]
    x, N = [0.0, 1e-4], [100.0, 100.0]
    for bad in (np.zeros(3), np.zeros((law.state_size, 1)), "abc"):
        with pytest.raises(ValueError, match="state must"):
            march(law, x, N, state=bad)
    for fill in (math.nan, math.inf):
        with pytest.raises(ValueError, match="state"):
            march(law, x, N, state=np.full(law.state_size, fill))
        s = law.initial_state(0.0, 100.0)
        s[0] = fill
        with pytest.raises(ValueError, match="state"):
            march(law, x, N, state=s)


def test_march_state_from_issue_12():
    with pytest.raises(ValueError, match="state"):
        march(IwanClosedForm(1e5, 0.1, 100), [0, 1e-4], [100, 100], state=np.full(201, np.nan))
    with pytest.raises(ValueError, match="state"):
        march(DiscreteIwan(1e5, 0.1, 100, n=5), [0, 1e-4], [100, 100], state=np.full(6, np.nan))


@pytest.mark.parametrize(
    "row,value",
    [(7, -1.0), (7, 65.0), (7, 1.5), (4, 3.0), (4, -1.0), (3, 0.5), (3, 2.0)],
)
def test_iwan_state_integer_fields(row, value):
    """Iwan's stack depth (row 7) in [0, max_depth], base code (row 4) in
    {0, 1, 2}, direction (row 3) in {-1, 0, 1}: what its kernels index by."""
    s = LAW.initial_state()
    s[row] = value
    with pytest.raises(ValueError, match="state"):
        march(LAW, [0.0, 1e-4], [100.0, 100.0], state=s)


def test_iwan_state_beyond_the_stack_may_hold_anything():
    """Rows past the live reversal points are never read: NaN there is fine,
    and the march equals one from the clean state."""
    s = LAW.initial_state()
    dirty = s.copy()
    dirty[9:] = np.nan
    x, N = np.linspace(0.0, 3e-4, 20), np.full(20, 100.0)
    np.testing.assert_array_equal(march(LAW, x, N, state=dirty)[0], march(LAW, x, N, state=s)[0])
    s[7] = 2.0
    s[9:15] = np.nan  # two live reversal points that are not finite
    with pytest.raises(ValueError, match="live reversal points"):
        march(LAW, x, N, state=s)


def test_register_refuses_a_taken_name_and_non_laws():
    from dataclasses import dataclass

    from jointdyn.laws import register

    @dataclass(frozen=True)
    class Other(Iwan):
        """Another law."""

    with pytest.raises(ValueError, match="already registered"):
        register("iwan", Other)
    with pytest.raises(ValueError, match="ContactLaw subclass"):
        register("not-a-law", dict)
    with pytest.raises(ValueError, match="fixed parameter"):
        register("not-a-law", Iwan, fixed={"no_such": 1})
    assert "not-a-law" not in law_names()
