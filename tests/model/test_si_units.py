"""Units that are SI already skip pint (its registry is slow to build); pint agrees with them."""

import pytest

from lagrangian.model import units


@pytest.mark.parametrize("unit", sorted(units._SI_UNITS))
def test_si_units_need_no_conversion_and_pint_agrees(unit):
    assert units.check_unit(unit, "f", None) == unit
    assert units.to_si(1.25, unit, "f") == 1.25
    quantity = units.registry().Quantity(1.25, units._unit(unit))
    assert quantity.to_base_units().magnitude == pytest.approx(1.25, rel=1e-15)


def test_force_units_of_lengths_and_angles():
    assert units.generalized_force_unit("m") == "N"
    assert units.generalized_force_unit("rad") == "N*m"
    assert units.generalized_force_unit("cm") == "J/cm"
