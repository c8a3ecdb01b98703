"""Physical parameters a preset carries: modal ranges per kind and season, and constants.

Every setting is declared once, in the annotation of its field below (type, unit, bounds,
default, help: :class:`~treeanim.model.declare.Param`); the preset reader, the simulations'
setters, the preset writer (app/save.py), the viewer's panel and the command line's
``--physics`` all take it from there (docs/design.md, "Adding a setting"). The classes are
frozen pydantic dataclasses: checked on construction and on ``dataclasses.replace``, a refusal
is one :class:`~treeanim.model.declare.SettingError` line. These are plain data; the physics
package interprets them (docs/design.md §4–§6).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import field
from typing import Annotated

from pydantic import field_validator

from .declare import Param, SettingError, params_of, settings

__all__ = ["ModeRange", "SeasonModes", "PhysicsParams", "PARAMS", "SCALAR_KEYS", "MODE_PARAMS", "WOOD_TYPES",
           "SettingError", "check_physics"]

#: A natural frequency (Hz): from a crown's slow sway to the stiffest twig beam theory gives
#: (the paper's oscillators stay finite at 1e4 Hz, whatever the step).
Frequency = Annotated[float, Param(1e-3, 1e4, unit="Hz", fmt="%.2f", label="f",
                                   help="Natural frequency of a mode (Eqs. 20-22).")]
#: A damping ratio: (2πf)² and 2ζω stay finite up to 1e3 (Euler included).
DampingRatio = Annotated[float, Param(0.0, 1e3, fmt="%.3f", label="ζ", help="Damping ratio of a mode (Eqs. 20-22).")]


@settings("ModeRange")
class ModeRange:
    """Ranges of natural frequency (Hz) and damping ratio for one kind of object, [min, max]."""

    f: tuple[Frequency, Frequency]
    zeta: tuple[DampingRatio, DampingRatio]

    @field_validator("f", "zeta")
    @classmethod
    def _ordered(cls, pair):
        if pair[0] > pair[1]:
            raise ValueError(f"expected [min, max] with min <= max, got {list(pair)}")
        return pair


@settings("SeasonModes")
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


def _positive(hi: float, unit: str = "", **kw) -> Param:
    """A quantity that must be > 0 (a stiffness, the air's density ...), at most ``hi``."""
    return Param(0.0, hi, lo_open=True, unit=unit, **kw)


def _material(lo: float, hi: float, unit: str, **kw) -> Param:
    """A material's density or modulus in [lo, hi], far beyond any plant either way (near 0 the
    tree model's masses and stiffnesses overflow)."""
    return Param(lo, hi, unit=unit, **kw)


def _non_negative(hi: float, unit: str = "", **kw) -> Param:
    """A quantity 0 switches off (a gain, a drag, a twist ...), at most ``hi``."""
    return Param(0.0, hi, unit=unit, **kw)


# The upper bounds: far beyond any plant or air, small enough that every state of the simulation
# stays finite (a gain of 1e308 or a damping scale of 1e300 overflowed it).
@settings("physics")
class PhysicsParams:
    """Everything the simulation takes from a preset: the modal ranges per season, and the
    constants declared below (each field's ``help`` says what it is).

    ``summer`` and ``winter`` hold f and ζ ranges per kind at season 0 and season 1
    (interpolated in between). Change one with ``dataclasses.replace(params, ei_max=...)``
    (checked like construction).

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
    ei_max: Annotated[float, _positive(
        1e12, "N·m²", label="EI_max", log=True,
        help="EI_max of Eq. 10: the flexural rigidity of the tree's thickest section (N·m²/rad·m, i.e. the "
             "bending stiffness k in N·m/rad of a segment of diameter D_max).")] = 2.5e4
    stiffness_exponent: Annotated[float, _non_negative(8.0, help="m of Eq. 10 (4 for a tapered circular beam).")] = 4.0
    twist_c0: Annotated[float, _non_negative(
        100.0, help="c0 of Eq. 11 for branches and blades, per unit of the object's root stiffness k0: "
                    "gamma = 0.5 pi sgn(L'_v)(1 - exp(-c0 |L'_v| / k0)) / n. Scaling by k0 lets one constant serve a "
                    "trunk and a twig, whose twisting moments differ by 1e6; 0: no twist.")] = 0.25
    leaf_zeta_w_scale: Annotated[float, _non_negative(
        100.0, help="Leaves' zeta_w multiplier (§4.4: more drag across the lamina).")] = 1.5
    leaf_zeta_v_scale: Annotated[float, _non_negative(100.0, help="Leaves' zeta_v multiplier (§4.4).")] = 0.5
    wind_gain_branch: Annotated[float, _non_negative(
        1e3, "N·s/m³", help="The paper's drag gain of branches: load = gain × exposed area × wind velocity.")] = 3.0
    wind_gain_leaf: Annotated[float, _non_negative(1e3, "N·s/m³", help="The paper's drag gain of leaves.")] = 0.5
    wind_gain_blade: Annotated[float, _non_negative(1e3, "N·s/m³", help="The paper's drag gain of grass blades.")] = 3.0
    wood_density: Annotated[float, _material(
        1e-3, 1e4, "kg/m³", help="Wood density: the paper's base-excitation inertia (docs/design.md §6 step 3) and the "
                           "tree model's segment masses.")] = 700.0
    leaf_density: Annotated[float, _material(1e-3, 1e4, "kg/m³", help="Density of petioles and laminas (their masses).")] = 500.0
    lamina_thickness: Annotated[float, Param(
        1e-6, 0.05, unit="m", help="Thickness of a leaf lamina (and of a grass blade), for its mass and its "
                                   "bending as it folds in the flow.")] = 3.0e-4
    leaf_twist_c0: Annotated[float, _non_negative(
        100.0, help="twist_c0 for leaves (their petioles twist more readily than wood).")] = 0.5
    leaf_youngs_modulus: Annotated[float, _material(
        1.0, 1e12, "Pa", help="The tree model (docs/design.md §12): Young's modulus E of petioles (EI = E pi D^4 / 64).")] = 1.0e9
    blade_youngs_modulus: Annotated[float, _material(
        1.0, 1e12, "Pa", help="The tree model: the effective modulus of grass blades, bent as a round rod as wide as the "
                         "blade: 5e5 Pa gives a 12 mm blade EI = 5e-4 N·m² at its base, that of a keeled blade with "
                         "its midrib, so a meadow bends visibly in a 5 m/s breeze and lies over in a 30 m/s "
                         "gale.")] = 5.0e5
    air_density: Annotated[float, _positive(
        10.0, "kg/m³", help="rho of the air, for the drag 1/2 rho C A |U_rel| U_rel (the tree model).")] = 1.2
    drag_branch: Annotated[float, _non_negative(
        10.0, help="C_d of a branch across the flow (the tree model; the paper's modes='physical' damping). A "
                   "cylinder's: the crown's shelter is the wind's canopy profile, not a smaller coefficient, so "
                   "a crown catches what measured crowns do.")] = 1.2
    drag_leaf: Annotated[float, _non_negative(
        10.0, help="C_n of a lamina's normal force (a flat plate's); leaves reconfigure in a gale.")] = 1.2
    drag_blade: Annotated[float, _non_negative(10.0, help="C_d of a grass blade.")] = 1.0
    leaf_flutter: Annotated[float, _non_negative(
        1.5, "rad", help="The tree model: the largest twist of a leaf's flutter about its petiole in a strong wind "
                         "(treeanim.physics.treestep).")] = 0.35
    wood_youngs_modulus: Annotated[float, _material(
        1.0, 1e12, "Pa", help="The effective Young's modulus E of the branches' wood: the tree model's joints and the "
                         "paper's modes='physical' (see WOOD_TYPES).")] = 6.0e9
    leaf_area_index: Annotated[float, _positive(
        20.0, "m²/m²", help="The tree model: the crown's leaf area per unit of its ground projection (broadleaf "
                            "crowns 3-6, Bréda 2003). A tree's leaves stand for clusters: each carries the mass, "
                            "drag and petiole of as many real leaves as give its full crown this index (at least "
                            "one).")] = 4.0
    wood_damping: Annotated[float, _non_negative(
        10.0, help="The damping ratio of the wood and the stem's structure (the tree model's joints, the paper's "
                   "modes='physical'), to which the drag of the crown adds.")] = 0.03

    def modes(self, kind: str, season: float) -> ModeRange | None:
        """f and ζ ranges for ``kind``, linearly interpolated at ``season`` in [0, 1]."""
        a, b = self.summer.of(kind), self.winter.of(kind)
        if a is None or b is None:
            return a or b
        s = min(max(float(season), 0.0), 1.0)

        def lerp(p, q, param):  # (kept in range and order should rounding step an ulp out)
            ends = sorted((p[0] + (q[0] - p[0]) * s, p[1] + (q[1] - p[1]) * s))
            return tuple(min(max(x, param.lo), param.hi) for x in ends)

        return ModeRange(lerp(a.f, b.f, MODE_PARAMS["f"]), lerp(a.zeta, b.zeta, MODE_PARAMS["zeta"]))


#: The scalar settings of a preset's [physics] table, by name, in declaration order.
PARAMS = params_of(PhysicsParams)
#: Their names.
SCALAR_KEYS = tuple(PARAMS)
#: The declarations of a mode range's f and zeta (each end of the pair).
MODE_PARAMS = params_of(ModeRange)

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
    """Raise ValueError if ``p`` cannot drive a simulation of these kinds: not a PhysicsParams
    (whose values its construction checked), or no f/ζ range for a kind the tree has.

    Parameters
    ----------
    p : PhysicsParams
    kinds : iterable of str
        The kinds of object the tree has ('branch', 'leaf', 'blade').
    """
    if not isinstance(p, PhysicsParams):
        raise ValueError(f"physics must be a PhysicsParams, got {type(p).__name__}")
    for kind in kinds:
        if p.summer.of(kind) is None and p.winter.of(kind) is None:
            raise ValueError(f"physics: no f/zeta range for kind {kind!r}, which the tree has")
