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


def test_init_kernel_writes_the_whole_virgin_state():
    """The third kernel of the contract: init(params, x0, n0, s) writes s in
    full (a buffer full of NaN comes back finite), is what initial_state
    returns, and the law is at rest there (T = 0 at x0, stick-slip for
    n0 > 0, separation for n0 <= 0)."""
    from law_cases import registry_laws

    from jointdyn.laws import SEPARATION, STICK_SLIP

    for name, _, law in registry_laws(kt=2e5, mu=0.4, n_ref=120.0):
        for x0, n0 in ((0.0, 120.0), (3.7e-4, 60.0), (-2e-3, 0.0)):
            s = np.full(law.state_size, np.nan)
            law.init(law.params, x0, n0, s)
            assert np.all(np.isfinite(s)), name
            np.testing.assert_array_equal(s, law.initial_state(x0, n0))
            s_new = np.empty_like(s)
            T, _, code = law.step(law.params, s, s_new, x0, n0)
            assert T == 0.0, name
            assert code == (STICK_SLIP if n0 > 0 else SEPARATION), name
        np.testing.assert_array_equal(law.initial_state(1e-4), law.initial_state(1e-4, law.n_ref))
