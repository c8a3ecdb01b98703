"""The boundary checks (treeanim/validate.py) name the argument and refuse what they should."""

from __future__ import annotations

import math

import numpy as np
import pytest

from treeanim.validate import finite_float, finite_vector3, float_within, positive_float


def test_each_check_accepts_its_values_and_names_the_argument_otherwise():
    assert finite_float("x", "2.5") == 2.5 and positive_float("x", 1e-300) == 1e-300
    assert float_within("x", 0, 0, 1) == 0.0 and float_within("x", 1, 0, 1) == 1.0
    np.testing.assert_array_equal(finite_vector3("v", (1, 2, 3)), [1.0, 2.0, 3.0])
    for check, bad in ((finite_float, math.nan), (finite_float, "a"), (positive_float, 0.0),
                       (positive_float, -math.inf), (lambda n, x: float_within(n, x, 0, 1, " m"), 1.5),
                       (finite_vector3, (1, 2)), (finite_vector3, (1, 2, math.inf))):
        with pytest.raises(ValueError, match="^speed "):
            check("speed", bad)
