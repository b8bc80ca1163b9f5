"""One home per concept: law labels registered with the law, output helpers, the break rule of HB branches."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from jointdyn.figures._registry import model_label
from jointdyn.laws import ContactLaw, law_label, law_names, register
from jointdyn.laws import _base


def test_builtin_laws_carry_their_labels():
    assert law_label("iwan") == "exact Iwan model"
    assert model_label("iwan") == "exact Iwan model (iwan)"
    assert model_label("jenkins") == "Jenkins element (jenkins)"
    assert model_label("not-a-law") == "not-a-law"
    assert all(law_label(n) for n in law_names())


def test_a_law_registered_without_a_label_is_named_by_its_name(monkeypatch):
    @dataclass(frozen=True, eq=False)
    class _Plain(ContactLaw):
        """A law of a test."""

    monkeypatch.setattr(_base, "_REGISTRY", dict(_base._REGISTRY))
    register("plain-test-law", _Plain)
    register("labelled-test-law", _Plain, label="a labelled law")
    assert law_label("plain-test-law") == "plain-test-law" == model_label("plain-test-law")
    assert model_label("labelled-test-law") == "a labelled law (labelled-test-law)"
    with pytest.raises(ValueError, match="model"):
        law_label("no-such-law")
