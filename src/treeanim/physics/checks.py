"""The physics modules' argument checks, from :mod:`treeanim.validate` (simulation.py and
wind.py import them from here; the names live there)."""

from ..validate import finite_float, finite_vector3

__all__ = ["finite_float", "finite_vector3"]
