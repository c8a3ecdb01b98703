"""Wind over trees: wind models behind one base class and a registry.

Every wind model subclasses :class:`WindField` (``field.py``: direction, speed, the fitted
box, the checks of ``sample``, the settings' properties) and is registered by name in
:data:`WIND_MODELS` (:func:`register_wind_model`), with its own settings declared once in its
``Params`` (``model/declare.py``); ``WindField(model=NAME, ...)`` builds one. Registered here:
``"physical"`` (:class:`PhysicalWind`, ``physical.py``; the default) and ``"paper"``
(:class:`PaperWind`, ``paper.py``; Hu, Chiba & He 2012). docs/design.md, "Adding a wind model",
shows how to add one.

``WindField(model="physical")`` (docs/design.md §12, issue 11) is weather-like wind:

* **Turbulence in metres.** Three independent Gaussian fields (along-wind u, vertical v,
  lateral w) on one periodic tile of 256 × 48 × 64 cells covering 16 L × 3 L × 4 L (along,
  up, across the wind), L the along-wind integral length scale (``length_scale``, by
  default the canopy height). The tile is independent of any tree's box, so every tree of a
  scene stands in one field. The 3-D spectrum is (k² + k0²)^−(β+2)/2 with k0 = 1/(1.339 L),
  so the spectrum along any line is the von Kármán form (k1² + k0²)^−β/2: f^−β in the
  inertial range, flat below the energy-containing eddies (one integral scale L for all
  three components; canopy flows' shorter cross-wind scales, about L/3, are not modelled). Its Fourier amplitudes are
  pre-compensated for trilinear interpolation (exactly along the wind, on average across
  it), so the spectrum at a fixed point keeps its slope up to about half the grid's Nyquist
  frequency U·12/(2L).
* **A landscape without a period** (``turbulence.py``). The tile is read through blocks:
  7 L long along the wind and, within each, L wide across it, each pair of blocks at its own
  hashed whole-cell offset into the tile. Neighbouring blocks share a ramp L wide where their
  weights w₀, w₁ (w₀² + w₁² = 1) hand over smoothly, so the variance stays exact and the
  field continuous. A block with its ramps spans half the tile's period, and points farther
  apart than a block never share an offset: no two places of the ground see the same wind
  (the tile still repeats every 3 L up). The coherence of points across the wind falls with
  distance much as Davenport's exp(−a·f·Δ/U) does, a ≈ 5–8 (measured; REALISM.md: 7–10).
* **Taylor's frozen turbulence.** The blocks and the tile are carried downwind at the mean
  speed at the canopy top, so a gust reaches a point d metres downwind d/U seconds later and
  gusts come faster in stronger wind.
* **Evolution, no loop.** The across-wind blocks slide across the wind, one block for every
  4 L the air travels (one way in even along-wind blocks, the other way in odd ones), so
  each eddy fades out and another fades in over about 4 L / U seconds and nothing repeats:
  a point's autocorrelation is ~0 beyond a few L / U.
* **Canopy profile.** Mean speed ``speed``·ln((y − d)/z0)/ln((h − d)/z0) above the canopy
  height h (d = 0.7 h, z0 = 0.1 h) and ``speed``·exp(a(y/h − 1)) inside it (a ≈ 3.03, so
  the two meet smoothly). Standard deviations σ_u : σ_w(lateral) : σ_v(vertical) =
  1 : 0.75 : 0.5 with σ_u = ``turbulence``·``speed`` at and above h, decaying as
  exp(y/h − 1) inside the canopy (the intensity rises towards the ground).
* **Gusts.** ``gust_rate`` gusts a minute, each a front across the wind with a sharp rise
  (0.5 L_g) and a slower decay (1.5 L_g) of peak ``gust_strength``·U·A (A uniform in
  [0.5, 1.5]), carried at the wind speed; their mean is subtracted, so they are gusts and
  lulls about the set mean. L_g (``gust_length``) is the atmospheric surface layer's
  along-wind integral scale at the canopy top (EN 1991-1-4, Annex B: 22 m over a 2.5 m
  canopy, 40 m over a 10 m one), not the canopy's: gusts are the large eddies that sweep
  down into the canopy, several trees long. Where gusts come faster than that allows, a
  gust's rise and decay shrink to fit the interval between gusts. They come in lanes
  1.5 L_g wide across the wind (half the length across as along, as in isotropic
  turbulence), each lane its own gusts, blended with the next lane's over a ramp L_g/2
  wide (as the turbulence's blocks are).
* **Mean direction.** Every fluctuation across the wind has zero mean by construction
  (symmetric Gaussian noise, no rescaling), so the long-run mean wind points along
  ``direction``.

``WindField(model="paper")`` keeps the three-dimensional 1/f^β field of §4.3 (Eqs. 13–18)
exactly. Three independent periodic noise grids (``fbm_noise``) give the along-wind (u),
vertical (v) and lateral (w) turbulence. ``WindField`` samples them by periodic trilinear
interpolation, shapes them with the logarithmic mean profile (Eq. 16) and the normalisation
of Eq. 17, and turns the result into a world velocity along the user's wind direction
(Eq. 18). Choices made there (docs/design.md §7 leaves them open):

* **Grid frame.** The grids are sampled in the *wind's own frame*: a point is scaled by the
  bounds to [0, 1]³, then to grid units (× (N − 1)), and its grid coordinates are its
  components along (û, v̂, ŵ) = (along wind, vertical, lateral). For a wind along +x this is
  exactly Eq. 17; for any other direction the frozen turbulence still travels downwind (at
  c5 cells/s) and drifts laterally (c6 cells/s). Changing the direction rotates the sampling
  frame, so the turbulence seen by a fixed point jumps when the direction changes.
* **Height.** The mean profile uses the world height h = y in metres (ground at y = 0), not
  the scaled coordinate: W(h) = c1·ln(c2·h) for h > 1/c2, else 0.
* **Defaults.** ``c2 = 50 / H`` (the profile starts at 2 % of the tree top H, the top of
  the bounds) and ``c1 = 1 / ln(c2·H)`` so W(H) = 1 and ``speed`` is the mean-profile speed at
  the tree top. ``c3 = 0.5``, ``c4 = 1.0``, ``c5 = 4`` cells/s, ``c6 = 0.5`` cells/s.

Named winds by Beaufort number (:data:`WIND_PRESETS`, :func:`wind_preset`,
``WindField.from_preset``): calm, breeze, windy, gale, storm.
"""

import numpy as np

from .field import DEFAULT_MODEL, WIND_MODELS, WindField, WindParams, register_wind_model, wind_model
from .paper import PaperParams, PaperWind, fbm_noise
from .physical import SIGMA_RATIOS, PhysicalParams, PhysicalWind
from .settings import DEFAULT_BOUNDS, MAX_SPEED, WIND_PRESETS, named_wind, wind_preset

#: The registry under its older name (the same dict).
MODELS = WIND_MODELS


def fit_to_tree(wind, rest_positions) -> None:
    """Fit ``wind`` to a tree's rest box if it has no bounds of its own (None or
    :data:`DEFAULT_BOUNDS`); a field with neither ``fit`` nor ``bounds`` needs none.

    Parameters
    ----------
    wind : object with ``sample`` (and ``fit`` or ``bounds``)
    rest_positions : (N, 3) float
    """
    if not (hasattr(wind, "fit") or hasattr(wind, "bounds")):
        return
    b = getattr(wind, "bounds", None)
    if b is not None:
        try:
            if not np.allclose(np.asarray(b, float), DEFAULT_BOUNDS):
                return
        except (TypeError, ValueError):
            return
    X = np.asarray(rest_positions, float)
    box = (tuple(map(float, X.min(axis=0))), tuple(map(float, X.max(axis=0))))
    if hasattr(wind, "fit"):
        wind.fit(box)
    else:
        wind.bounds = box
    if hasattr(wind, "fit_cover"):
        wind.fit_cover(canopy_cover(X))


def canopy_cover(rest_positions) -> float:
    """The fraction of the ground under crowns, around a tree or over a scene: the plan area
    its nodes cover (cells half its height wide: a gap narrower than that is sheltered, the
    canopy's eddies are as large as its height) over its box widened by half its
    height on every side (the ground whose wind it shelters).

    A lone tree covers a quarter or less (the small and large cherries 0.2–0.3), an orchard
    about half, a closed stand or a meadow's sward nearly all of it: the wind decays into a
    closed canopy (Raupach's mixing layer), while a lone crown stands in the open wind.

    Parameters
    ----------
    rest_positions : (N, 3) float
        The nodes, y up, the ground at y = 0.

    Returns
    -------
    float
        In [0, 1].
    """
    X = np.asarray(rest_positions, float)
    height = float(X[:, 1].max())
    if not height > 0.0:
        return 0.0
    cell = 0.5 * height
    lo = X[:, [0, 2]].min(axis=0) - 0.5 * height
    span = X[:, [0, 2]].max(axis=0) + 0.5 * height - lo
    ij = np.floor((X[:, [0, 2]] - lo) / cell).astype(np.int64)
    covered = len(np.unique(ij[:, 0] * (int(span[1] / cell) + 2) + ij[:, 1])) * cell * cell
    return float(min(covered / (span[0] * span[1]), 1.0))

__all__ = ["fit_to_tree", "canopy_cover", "fbm_noise", "WindField", "WindParams", "WIND_MODELS", "DEFAULT_MODEL", "register_wind_model",
           "wind_model", "PhysicalWind", "PhysicalParams", "PaperWind", "PaperParams", "WIND_PRESETS", "wind_preset", "named_wind",
           "MODELS", "DEFAULT_BOUNDS", "MAX_SPEED", "SIGMA_RATIOS"]
