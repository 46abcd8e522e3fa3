"""The behaviours a scenario can name, and their parameters, as Python sees them."""

from __future__ import annotations

import pytest

import colcos


def test_every_behaviour_documents_its_parameters():
    names = colcos.behaviours()
    assert {"wander", "avoid", "follow", "forage"} <= set(names)
    for name in names:
        params = colcos.behaviour_params(name)
        assert params, name
        for p in params:
            assert set(p) == {"name", "type", "default", "meaning"}
            assert p["name"] and p["meaning"], (name, p)
    follow = {p["name"]: p for p in colcos.behaviour_params("follow")}
    assert "channel" in follow and "speed" in follow


def test_an_unknown_behaviour_names_itself():
    with pytest.raises(colcos.TaskError, match="nope"):
        colcos.behaviour_params("nope")
