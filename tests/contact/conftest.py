"""Shared helpers for the contact tests: the compiled module and finite differences."""

import numpy as np
import pytest

from abdsim._native import _core


class FiniteDifferences:
    """Central differences, for checking analytic gradients and Hessians."""

    @staticmethod
    def gradient(f, x, h=1e-6):
        x = np.asarray(x, dtype=float)
        g = np.zeros_like(x)
        for i in range(x.size):
            e = np.zeros_like(x)
            e[i] = h
            g[i] = (f(x + e) - f(x - e)) / (2 * h)
        return g

    @staticmethod
    def jacobian(g, x, h=1e-6):
        x = np.asarray(x, dtype=float)
        cols = []
        for i in range(x.size):
            e = np.zeros_like(x)
            e[i] = h
            cols.append((np.asarray(g(x + e)) - np.asarray(g(x - e))) / (2 * h))
        return np.stack(cols, axis=-1)


@pytest.fixture(scope="session")
def contact():
    return _core.contact


@pytest.fixture(scope="session")
def fd():
    return FiniteDifferences


@pytest.fixture
def rng():
    return np.random.default_rng(20240601)
