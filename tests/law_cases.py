"""Contact laws for the law tests, built from the registry.

Every law test iterates :func:`jointdyn.laws.law_names`, so that a law module
dropped into ``jointdyn/laws`` is tested without editing the tests; the
parameter sets come from each law's declared parameters
(:func:`jointdyn.laws.law_parameters`), never from a list of known laws.
"""

from __future__ import annotations

import math

from hypothesis import strategies as st

from jointdyn.laws import law_names, law_parameters, make_law


def _edge_values(p):
    """Values of one law parameter at the edges of its declared range."""
    if p.kind == "choice":
        return list(p.choices)
    if p.kind == "int":
        lo = int(p.low)
        return [v for v in (lo, lo + 2) if v <= p.high]
    vals = [v for v in (p.low, p.high) if math.isfinite(v)]
    if math.isfinite(p.low) and math.isfinite(p.high):
        vals.append(0.5 * (p.low + p.high))
    return vals


#: with ``small=True`` an integer parameter whose default lies further than
#: this above its lower bound starts at ``low + SMALL_OFFSET`` instead
SMALL_SPAN = 40
SMALL_OFFSET = 6


def variants(name, small=False):
    """Law-parameter sets of ``name`` for the tests: the defaults, then each
    parameter alone at the edges of its range (both ends of an integer range
    start: the stack or element count where the rules bite).

    ``small=True`` replaces a large integer default (e.g. 1000 elements) by
    a small value in the first set, for tests whose oracle needs few
    elements (finite differences of a march).
    """
    base = {}
    if small:
        for p in law_parameters(name):
            if p.kind == "int" and p.default > p.low + SMALL_SPAN:
                base[p.name] = int(p.low) + SMALL_OFFSET
    out = [base]
    for p in law_parameters(name):
        for v in _edge_values(p):
            if v != base.get(p.name, p.default):
                out.append({**base, p.name: v})
    return out


def case_id(name, params):
    """Readable test id of a law and its parameters."""
    return name + "".join(f"-{k}{v}" for k, v in sorted(params.items()))


def registry_laws(kt, mu, n_ref, small=False):
    """``(id, name, law)`` for every registered law and every parameter set of :func:`variants`."""
    return [
        (case_id(name, params), name, make_law(name, kt=kt, mu=mu, n_ref=n_ref, **params))
        for name in law_names()
        for params in variants(name, small)
    ]


def _param_values(p):
    """Hypothesis strategy of one law parameter within its declared range
    (integers near the low end or the default, so that marches stay short)."""
    if p.kind == "choice":
        return st.sampled_from(p.choices)
    if p.kind == "int":
        lo = int(p.low)
        hi = int(min(p.high, lo + 40))
        return st.integers(lo, hi) | st.just(p.default)
    hi = p.high if math.isfinite(p.high) else max(4.0 * abs(p.default), p.low + 1.0)
    lo = p.low if math.isfinite(p.low) else -hi
    return st.floats(lo, hi)


@st.composite
def laws(draw, names=None):
    """A registered law (any of ``names``, default all) with random kt, mu,
    n_ref and random law parameters."""
    name = draw(st.sampled_from(sorted(names or law_names())))
    kt = 10.0 ** draw(st.floats(3.0, 8.0))
    mu = draw(st.floats(0.01, 1.0))
    n_ref = 10.0 ** draw(st.floats(0.0, 4.0))
    params = {p.name: draw(_param_values(p)) for p in law_parameters(name)}
    return make_law(name, kt=kt, mu=mu, n_ref=n_ref, **params)
