"""Contact-law options shared by the commands, generated from the law registry.

``--model NAME`` (help listing every registered law with its one-line
summary and its law parameters), ``--law-param NAME=VALUE`` (repeatable) and
``--n N`` (shorthand for ``--law-param n=N``, refused for a model without
that parameter).
"""

from __future__ import annotations


def model_help(default: str) -> str:
    """Help text of ``--model``: every registered law, its summary and parameters."""
    from ..laws import law_names, law_parameters, law_summary

    items = []
    for name in law_names():
        params = ", ".join(p.name for p in law_parameters(name))
        items.append(f"{name}: {law_summary(name)}" + (f" [law parameters: {params}]" if params else ""))
    return f"contact law (default {default}); " + "; ".join(items)


def add_law_arguments(p) -> None:
    """``--law-param`` and ``--n`` (``--model`` is the command's own, with :func:`model_help`)."""
    p.add_argument("--law-param", action="append", default=None, metavar="NAME=VALUE", dest="law_param",
                   help="law-specific parameter of --model (repeatable); see jointdyn.laws.law_parameters, "
                        "e.g. --law-param capacity=64 for iwan, --law-param n=200 for discrete")
    p.add_argument("--n", type=int, default=None,
                   help="shorthand for --law-param n=N (number of Jenkins elements of --model discrete)")


def law_params(args) -> dict:
    """The law parameters given on the command line, validated for ``args.model``.

    Returns every law-specific parameter of the model with its value (given
    or default), converted to its kind.

    Raises
    ------
    ValueError
        Malformed ``NAME=VALUE``, a name given twice, ``--n`` for a model
        without a parameter ``n``, an unknown parameter (the message lists
        the model's parameters) or a value out of range.
    """
    from ..laws import canonical_law_params, law_names, law_parameters, make_law

    given = {}
    for item in args.law_param or ():
        key, sep, value = str(item).partition("=")
        key = key.strip()
        if not sep or not key:
            raise ValueError(f"--law-param must be NAME=VALUE, got {item!r}")
        if key in given:
            raise ValueError(f"--law-param {key} is given twice")
        given[key] = value.strip()
    params = {p.name: p for p in law_parameters(args.model)}
    if args.n is not None:
        if "n" not in params:
            listed = ", ".join(params) or "none"
            with_n = ", ".join(m for m in law_names() if "n" in {p.name for p in law_parameters(m)})
            raise ValueError(f"--n applies to models with a law parameter n ({with_n}); --model {args.model} "
                             f"has law parameters: {listed}")
        if "n" in given:
            raise ValueError("--n and --law-param n=... are both given; give one")
        try:
            given["n"] = params["n"].check(args.n)
        except ValueError:
            raise ValueError(f"--n must be {params['n'].allowed()}, got {args.n!r}") from None
    try:
        out = dict(canonical_law_params(args.model, given))
    except ValueError as exc:
        raise ValueError(f"--law-param {exc}") from None
    try:  # the sizes the parameters set (a law's state) are bounded by the memory, before computing
        make_law(args.model, kt=1.0, mu=1.0, n_ref=1.0, **out)
    except ValueError as exc:
        msg = str(exc)
        if args.n is not None and msg.startswith("n "):
            raise ValueError(f"--n{msg[1:]}") from None
        raise ValueError(f"--law-param {msg}") from None
    return out
