"""The composition tables of dirac.compositions: consistency and the order each row claims.

The observed order of every row is measured by the splitting methods built from it
(``tests/rigidbody/test_splitting_methods.py::test_observed_convergence_order`` runs each
``lie-poisson-<suffix>`` and ``lie-poisson-sym-<suffix>`` against the exact flow); here
the rows are checked as data and against the conditions on ``sum gamma_i^k``.
"""

from __future__ import annotations

import math

import pytest

from dirac.compositions import COMPOSITIONS, MAIN_SUFFIXES, Composition, palindrome
from dirac.rigidbody.splitting import SCHEMES

ROWS = {row.suffix: row for row in COMPOSITIONS}


def test_suffixes_are_unique_and_the_contract_orders_are_there():
    assert len(ROWS) == len(COMPOSITIONS)
    for suffix in MAIN_SUFFIXES:
        assert ROWS[suffix].order == int(suffix)


@pytest.mark.parametrize("row", COMPOSITIONS, ids=lambda row: row.suffix)
def test_weights_sum_to_one_and_are_palindromic(row: Composition):
    assert math.isclose(math.fsum(row.coefficients), 1.0, rel_tol=0.0, abs_tol=1e-15)
    assert row.coefficients == tuple(reversed(row.coefficients))  # symmetric composition
    assert row.stages == len(row.coefficients) >= 1
    assert row.reference


@pytest.mark.parametrize("row", COMPOSITIONS, ids=lambda row: row.suffix)
def test_odd_power_sums_vanish_up_to_the_claimed_order(row: Composition):
    """A symmetric composition of a symmetric order-2 step has order ``p`` only if
    ``sum gamma_i^k = 0`` for the odd ``k = 3, ..., p - 1`` (Hairer, Lubich & Wanner,
    Sect. V.3.2); the first odd sum beyond is not zero, so the order is not higher."""
    for k in range(3, row.order, 2):
        assert abs(math.fsum(g**k for g in row.coefficients)) <= 1e-14, (row.suffix, k)
    assert abs(math.fsum(g ** (row.order + 1) for g in row.coefficients)) > 1e-4


@pytest.mark.parametrize("row", COMPOSITIONS, ids=lambda row: row.suffix)
def test_every_row_is_a_splitting_scheme_whose_order_is_measured(row: Composition):
    for prefix in ("lie-poisson-", "lie-poisson-sym-"):
        scheme = SCHEMES[prefix + row.suffix]
        assert scheme.coefficients == row.coefficients
        assert scheme.order == row.order


def test_palindrome_completes_the_middle_weight():
    weights = palindrome((0.25, 0.5))
    assert weights == (0.25, 0.5, -0.5, 0.5, 0.25)
    assert math.fsum(weights) == 1.0
