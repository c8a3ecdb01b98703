"""Physical parameters a preset carries: modal ranges per kind and season, and constants.

These are plain data; the physics package interprets them (docs/design.md §4–§6).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from ..validate import finite_float


@dataclass(frozen=True)
class ModeRange:
    """Ranges of natural frequency (Hz) and damping ratio for one kind of object."""

    f: tuple[float, float]
    zeta: tuple[float, float]


@dataclass(frozen=True)
class SeasonModes:
    """Mode ranges per kind for one season; a kind the tree lacks may be None."""

    branch: ModeRange | None = None
    leaf: ModeRange | None = None
    blade: ModeRange | None = None

    def of(self, kind: str) -> ModeRange | None:
        """The range for ``kind`` ('branch', 'leaf' or 'blade')."""
        return getattr(self, kind)


def _default_season() -> SeasonModes:
    return SeasonModes(
        branch=ModeRange((0.5, 1.0), (0.2, 0.5)),
        leaf=ModeRange((1.2, 1.8), (0.08, 0.12)),
        blade=ModeRange((0.8, 1.2), (0.13, 0.17)),
    )


@dataclass(frozen=True)
class PhysicsParams:
    """Everything the simulation takes from a preset.

    Attributes
    ----------
    summer, winter : SeasonModes
        f and ζ ranges per kind at season 0 and season 1 (interpolated in between).
    ei_max : float
        EI_max of Eq. 10, the flexural rigidity of the tree's thickest section (N·m²/rad·m,
        i.e. the bending stiffness k in N·m/rad of a segment of diameter D_max).
    stiffness_exponent : float
        m of Eq. 10 (4 for a tapered circular beam).
    twist_c0 : float
        c0 of Eq. 11 for branches and blades, per unit of the object's root stiffness k₀
        (dimensionless): γ = 0.5π·sgn(L′_v)(1 − exp(−c0·|L′_v|/k₀))/n. Scaling by k₀ lets one
        constant serve a trunk and a twig, whose twisting moments differ by 10⁶.
    leaf_zeta_w_scale, leaf_zeta_v_scale : float
        Leaves' ζ_w and ζ_v multipliers (§4.4: more drag across the lamina).
    wind_gain_branch, wind_gain_leaf, wind_gain_blade : float
        Drag gain per kind (N·s/m³): load = gain × exposed area × wind velocity.
    wood_density, leaf_density : float
        kg/m³: the paper's base-excitation inertia (docs/design.md §6 step 3) and the tree
        model's masses (segments, petioles, laminas).
    lamina_thickness : float
        Thickness of a leaf lamina (and of a grass blade) in metres, for its mass.
    leaf_twist_c0 : float
        ``twist_c0`` for leaves (their petioles twist more readily than wood).
    leaf_youngs_modulus : float
        The tree model (docs/design.md §12): Young's modulus E (Pa) of petioles (EI = EπD⁴/64).
    blade_youngs_modulus : float
        The tree model: the same for grass blades, an effective modulus, since the model
        bends a blade as a round rod as wide as the blade: 5e5 Pa gives a 12 mm blade
        EI ≈ 5e-4 N·m² at its base, that of a keeled blade with its midrib, so a meadow
        bends visibly in a 5 m/s breeze and lies over in a 30 m/s gale.
    air_density : float
        ρ of the air (kg/m³), for the drag ½ρ C A |U_rel| U_rel (the tree model).
    drag_branch, drag_leaf, drag_blade : float
        Drag coefficients (the tree model; the paper's ``modes="physical"`` damping): C_d of a
        branch across the flow, C_n of a lamina's normal force, C_d of a grass blade. A
        cylinder's (1.2) and a flat plate's (1.2): the crown's shelter is the wind's canopy
        profile (the wind inside a canopy falls off with depth), not a smaller coefficient.
        So a crown catches what measured crowns do (a drag coefficient of about 0.2 on its
        silhouette at a few m/s) and its leaves reconfigure in a gale.
    leaf_flutter : float
        The tree model: the largest twist (rad) of a leaf's flutter about its petiole in a
        strong wind (:mod:`treeanim.physics.treestep`).
    wood_youngs_modulus : float
        The effective Young's modulus E (Pa) of the branches' wood: the tree model's joints and
        the paper's ``modes="physical"`` (:mod:`treeanim.physics.physical`) (see
        :data:`WOOD_TYPES`).
    leaf_area_index : float
        The tree model: the crown's leaf area per unit of its ground projection (m²/m²;
        broadleaf crowns 3–6, Bréda 2003). A tree's leaves stand for clusters: each carries the
        mass, drag and petiole of as many real leaves as give its full crown this index (at
        least one), so a preset drawn with a few thousand leaves weighs and catches the wind as
        a real crown does.
    wood_damping : float
        The damping ratio of the wood and the stem's structure (the tree model's joints, the
        paper's ``modes="physical"``), to which the drag of the crown adds.

    Notes
    -----
    The defaults are tuned on the small cherry (m = 4): a 5 m/s wind at the tree top bends
    it by about 2 % of its height at the top (≈ 8 cm), its leaves bent and twisted by ≈ 15°
    (≈ 8° of twist); 25 m/s gives ≈ 8 % (≈ 30 cm), leaves at ≈ 55° (≈ 35° of twist) and
    twigs at ≈ 30°. With k ∝ D⁴ the
    stiffness scales with the tree's thickest diameter, so a preset of another size sets its
    own ``ei_max`` (and, for other petioles and laminas, ``wind_gain_leaf``). For the same
    response (2 % of the height at 5 m/s, leaves ≈ 15°): large_cherry ``ei_max = 9e5``,
    ``wind_gain_leaf = 0.15``; tulip_poplar ``ei_max = 7e5``, ``wind_gain_leaf = 0.01``;
    grassland ``ei_max = 1.7`` (blade tips ≈ 5 cm at 5 m/s, ≈ 20 cm at 25 m/s); beam
    ``ei_max = 50``.
    """

    summer: SeasonModes = field(default_factory=_default_season)
    winter: SeasonModes = field(default_factory=_default_season)
    ei_max: float = 2.5e4
    stiffness_exponent: float = 4.0
    twist_c0: float = 0.25
    leaf_zeta_w_scale: float = 1.5
    leaf_zeta_v_scale: float = 0.5
    wind_gain_branch: float = 3.0
    wind_gain_leaf: float = 0.5
    wind_gain_blade: float = 3.0
    wood_density: float = 700.0
    leaf_density: float = 500.0
    lamina_thickness: float = 3.0e-4
    leaf_twist_c0: float = 0.5
    leaf_youngs_modulus: float = 1.0e9
    blade_youngs_modulus: float = 5.0e5
    air_density: float = 1.2
    drag_branch: float = 1.2
    drag_leaf: float = 1.2
    drag_blade: float = 1.0
    leaf_flutter: float = 0.35
    wood_youngs_modulus: float = 6.0e9
    leaf_area_index: float = 4.0
    wood_damping: float = 0.03

    def modes(self, kind: str, season: float) -> ModeRange | None:
        """f and ζ ranges for ``kind``, linearly interpolated at ``season`` in [0, 1]."""
        a, b = self.summer.of(kind), self.winter.of(kind)
        if a is None or b is None:
            return a or b
        s = min(max(float(season), 0.0), 1.0)
        lerp = lambda p, q: (p[0] + (q[0] - p[0]) * s, p[1] + (q[1] - p[1]) * s)  # noqa: E731
        return ModeRange(lerp(a.f, b.f), lerp(a.zeta, b.zeta))


#: Scalar keys of a preset's [physics] table, each a finite positive number.
SCALAR_KEYS = tuple(
    k for k in PhysicsParams.__dataclass_fields__ if k not in ("summer", "winter")
)
#: The largest value of each scalar: far beyond any plant or air, small enough that every state
#: of the simulation stays finite (a gain of 1e308 or a damping scale of 1e300 overflowed it).
SCALAR_MAX = {
    "ei_max": 1e12, "stiffness_exponent": 8.0, "twist_c0": 100.0, "leaf_zeta_w_scale": 100.0,
    "leaf_zeta_v_scale": 100.0, "wind_gain_branch": 1e3, "wind_gain_leaf": 1e3, "wind_gain_blade": 1e3,
    "wood_density": 1e4, "leaf_density": 1e4, "lamina_thickness": 0.05, "leaf_twist_c0": 100.0,
    "leaf_youngs_modulus": 1e12, "blade_youngs_modulus": 1e12, "air_density": 10.0, "drag_branch": 10.0,
    "drag_leaf": 10.0, "drag_blade": 10.0,
    "leaf_flutter": 1.5, "wood_youngs_modulus": 1e12, "wood_damping": 10.0, "leaf_area_index": 20.0,
}
assert set(SCALAR_MAX) == set(SCALAR_KEYS)

#: Wood per type, for ``modes="physical"``: green density (kg/m³), the effective Young's modulus
#: of a standing tree (Pa) and the structure's damping ratio. Small clear green specimens give
#: 9–11 GPa (Wood Handbook, FPL-GTR-190, Table 5-3a); a standing tree sways as if softer (its
#: juvenile core, knots, the root plate's give): E ≈ 4 GPa fitted measured Douglas-fir sway
#: best (docs/REALISM). Damping: de-branched stems 1–8 % (Moore & Maguire 2005).
WOOD_TYPES = {
    "hardwood": {"wood_density": 900.0, "wood_youngs_modulus": 6.0e9, "wood_damping": 0.03},
    "softwood": {"wood_density": 800.0, "wood_youngs_modulus": 4.0e9, "wood_damping": 0.03},
}


def check_physics(p: PhysicsParams, kinds: Iterable[str]) -> None:
    """Raise ValueError naming the field if ``p`` cannot drive a simulation of these kinds.

    Parameters
    ----------
    p : PhysicsParams
    kinds : iterable of str
        The kinds of object the tree has ('branch', 'leaf', 'blade').
    """
    if not isinstance(p, PhysicsParams):
        raise ValueError(f"physics must be a PhysicsParams, got {type(p).__name__}")
    positive = ("ei_max", "wood_density", "leaf_density", "lamina_thickness",
                "leaf_youngs_modulus", "blade_youngs_modulus", "air_density", "leaf_area_index",
                "wood_youngs_modulus")
    for name in SCALAR_KEYS:
        x = finite_float(f"physics.{name}", getattr(p, name))
        if not (x > 0 if name in positive else x >= 0) or x > SCALAR_MAX[name]:
            raise ValueError(f"physics.{name} must be {'>' if name in positive else '>='} 0 and at most "
                             f"{SCALAR_MAX[name]:g}, got {x!r}")
    for season in ("summer", "winter"):
        sm = getattr(p, season)
        for kind in kinds:
            r = sm.of(kind)
            if r is None:
                if getattr(p, "winter" if season == "summer" else "summer").of(kind) is None:
                    raise ValueError(f"physics: no f/zeta range for kind {kind!r}, which the tree has")
                continue
            for i in (0, 1):
                f = finite_float(f"physics.{season}.{kind}.f", r.f[i])
                z = finite_float(f"physics.{season}.{kind}.zeta", r.zeta[i])
                if f <= 0:
                    raise ValueError(f"physics.{season}.{kind}.f must be > 0, got {r.f!r}")
                if z < 0:
                    raise ValueError(f"physics.{season}.{kind}.zeta must be >= 0, got {r.zeta!r}")
