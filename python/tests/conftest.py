"""Fixtures shared by the Python tests."""

import pytest

import aerial_chain as ac


@pytest.fixture(scope="session")
def window():
    """The built-in scenario `window` (its map is read once and never changed)."""
    return ac.Map.scenario("window")
