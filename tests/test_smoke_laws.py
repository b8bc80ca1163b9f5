"""First oracles for the kernel contract (more in the laws test modules)."""

import numpy as np

from jointdyn import DiscreteIwan, Iwan, march


def test_iwan_backbone_first_step():
    law = Iwan(kt=1e5, mu=0.1, n_ref=100.0)
    s0 = law.initial_state()
    s1 = np.empty_like(s0)
    keep = s0.copy()
    T, kT, code = law.step(law.params, s0, s1, 1e-5, 100.0)
    q = 1e5 * 1e-5 / 10.0
    assert np.isclose(T, 10.0 * (q - q * q / 4.0))
    assert np.array_equal(s0, keep)


def test_iwan_equals_discrete_random_walk():
    rng = np.random.default_rng(1)
    x = np.cumsum(rng.normal(size=3000)) * 2e-6
    N = np.full_like(x, 100.0)
    T1 = march(Iwan(kt=1e5, mu=0.1, n_ref=100.0), x, N)[0]
    T2 = march(DiscreteIwan(kt=1e5, mu=0.1, n_ref=100.0, n=4000), x, N)[0]
    assert np.max(np.abs(T1 - T2)) < 5e-3 * 10.0
