"""The navigation layer's old paths (before issue 26 moved it out of ``strapdown.algorithms``)
still work for one release: they warn and give the very objects of the new ones."""

from __future__ import annotations

import importlib
import sys

import pytest

import strapdown.navigation as nav


def test_old_navigation_module_warns_and_is_the_new_one():
    sys.modules.pop("strapdown.algorithms.navigation", None)
    with pytest.warns(DeprecationWarning, match="moved to strapdown.navigation"):
        old = importlib.import_module("strapdown.algorithms.navigation")
    for name in old.__all__:
        assert getattr(old, name) is getattr(nav, name), name


@pytest.mark.parametrize("name", ["InertialSolution", "MpInertialSolution",
                                  "integrate_inertial", "integrate_inertial_mp",
                                  "integrate_inertial_rates"])
def test_old_inertial_names_warn_and_are_the_new_ones(name):
    import strapdown.algorithms.velocity as velocity

    with pytest.warns(DeprecationWarning, match=f"strapdown.navigation.{name}"):
        assert getattr(velocity, name) is getattr(nav, name)


def test_an_unknown_name_is_still_an_attribute_error():
    import strapdown.algorithms.velocity as velocity

    with pytest.raises(AttributeError, match="no attribute 'integrate_nothing'"):
        velocity.integrate_nothing  # noqa: B018
