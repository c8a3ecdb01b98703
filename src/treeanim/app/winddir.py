"""The viewer's wind direction as one angle: degrees about +y from +x (the panel's slider)."""

from __future__ import annotations

import math

import numpy as np


def wind_direction(angle_deg: float) -> np.ndarray:
    """The horizontal unit vector at ``angle_deg`` about +y from +x (90° is −z)."""
    a = math.radians(angle_deg)
    return np.array([math.cos(a), 0.0, -math.sin(a)])


def wind_angle(direction) -> float:
    """Inverse of :func:`wind_direction`: degrees in [0, 360)."""
    d = np.asarray(direction, float)
    return math.degrees(math.atan2(-d[2], d[0])) % 360.0
