"""Bad input to the contact laws and to march: ValueError naming the parameter."""

import math

import numpy as np
import pytest

from jointdyn import DiscreteIwan, Iwan, Jenkins, make_law, march

GOOD = dict(kt=1e5, mu=0.1, n_ref=100.0)
BAD_VALUES = {
    "kt": [0.0, -1.0, math.nan, math.inf, "abc"],
    "mu": [-0.1, math.nan, math.inf, -math.inf],
    "n_ref": [0.0, -5.0, math.nan, math.inf],
}


@pytest.mark.parametrize("cls", [Iwan, DiscreteIwan, Jenkins])
@pytest.mark.parametrize("param,value", [(k, v) for k, vs in BAD_VALUES.items() for v in vs])
def test_bad_common_parameters(cls, param, value):
    with pytest.raises(ValueError, match=param):
        cls(**{**GOOD, param: value})


@pytest.mark.parametrize("name", ["iwan", "iwan-paper", "discrete", "jenkins"])
@pytest.mark.parametrize("param,value", [("kt", 0.0), ("mu", -1.0), ("n_ref", math.nan)])
def test_make_law_bad_parameters(name, param, value):
    with pytest.raises(ValueError, match=param):
        make_law(name, **{**GOOD, param: value})


@pytest.mark.parametrize("n", [0, -3, 1.5, math.nan, math.inf, True, "x"])
def test_discrete_bad_n(n):
    with pytest.raises(ValueError, match="n must"):
        DiscreteIwan(**GOOD, n=n)
    with pytest.raises(ValueError, match="n must"):
        make_law("discrete", **GOOD, n=n)


def test_jenkins_is_one_element():
    with pytest.raises(ValueError, match="n must be 1"):
        Jenkins(**GOOD, n=2)


def test_iwan_bad_options():
    with pytest.raises(ValueError, match="memory"):
        Iwan(**GOOD, memory="paper")
    with pytest.raises(ValueError, match="max_depth"):
        Iwan(**GOOD, max_depth=1)


def test_unknown_model_name():
    with pytest.raises(ValueError, match="model"):
        make_law("coulomb", **GOOD)


def test_good_parameters_accepted():
    for name in ("iwan", "iwan-paper", "discrete", "jenkins"):
        law = make_law(name, **GOOD, n=10)
        assert law.fy == pytest.approx(10.0)
    assert make_law("discrete", **GOOD, n=10).n == 10
    assert make_law("iwan-paper", **GOOD).memory == "last"
    assert Iwan(kt=1e5, mu=0.0, n_ref=100.0).fy == 0.0  # mu = 0 is allowed


LAW = Iwan(**GOOD)


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


def test_march_bad_state():
    with pytest.raises(ValueError, match="state must have shape"):
        march(LAW, np.zeros(3), np.ones(3), state=np.zeros(3))
    with pytest.raises(ValueError, match="state must have shape"):
        march(LAW, np.zeros(3), np.ones(3), state=np.zeros((LAW.state_size, 1)))
