"""Seeded procedural trees in the spirit of Weber & Penn (1995).

A preset gives the trunk and, per hierarchy level, how many children each branch carries,
where along it, at what branching and roll angles, with what length and radius ratios, taper,
curvature and gravity bend. Children on a parent's tip node share its cross-section (da Vinci's
rule), so the wood tapers through a fork without a step. Leaves spiral along the outer levels'
branches (and the leader's top), so many per metre of twig, with a share in tufts at the free
tips, their blades turned at random off facing up; grass blades are scattered roots in a patch
that may fade out at its edge. The same spec and seed give bit-identical arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .build import ObjectSpec, assemble, perpendicular
from .lamina import make_lamina
from .look import Bark
from .params import PhysicsParams
from .tree import Tree

UP = np.array([0.0, 1.0, 0.0])
GOLDEN_ANGLE = 137.50776


@dataclass(frozen=True)
class LevelSpec:
    """One branching level: the trunk (level 1) or the children of the level above."""

    segments: int = 1
    length: float = 1.0  # metres for the trunk, ratio to the parent's length otherwise
    length_var: float = 0.1
    cone: float = 0.0  # 0..1: children low on the parent are longer (a conical crown)
    # Metres for the trunk; for a child along its parent, the ratio to the parent's diameter at
    # the joint. Children on the parent's tip node ignore it: they share the tip's cross-section.
    diameter: float = 0.6
    taper: float = 0.3  # tip diameter = base diameter * (1 - taper)
    count: float = 0.0  # children per branch of the level above (mean; the total is exact)
    attach: tuple[float, float] = (1.0, 1.0)  # where along the parent children sit (fraction)
    down_angle: float = 35.0  # angle from the parent's axis, degrees
    down_var: float = 8.0
    roll: float = GOLDEN_ANGLE  # roll increment about the parent's axis between siblings
    roll_var: float = 20.0
    curvature: float = 0.0  # total bend along the branch, degrees
    gravity: float = 0.0  # droop toward the ground at the tip, degrees
    up: float = 0.0  # 0..1: tendency of the initial direction toward vertical
    lean: float = 0.0  # trunk only: lean from vertical, degrees


@dataclass(frozen=True)
class LeafSpec:
    """Leaves: petiole beams with a lamina, spiralling along the branches of ``levels``.

    Each node of those branches within ``attach`` (fraction of the branch's length), and of the
    trunk's top ``leader`` fraction, bears the leaves of the segment below it, so leaves are
    spread evenly per metre of twig; a further ``tip_share`` of all leaves sits in tufts at the
    free tips (tips no branch grows on from).
    """

    count: int = 0
    winter_count: int = 0
    levels: tuple[int, ...] = ()
    attach: tuple[float, float] = (0.0, 1.0)  # where along a branch leaves sit (fraction)
    leader: float = 0.0  # the trunk's top fraction (the leader's shoot) bears leaves too
    tip_share: float = 0.0  # share of the leaves in tufts at free tips
    tip_angle: float = 30.0  # down angle of a tip tuft's most upright leaves, degrees
    petiole_length: float = 0.03
    petiole_diameter: float = 0.002
    petiole_segments: int = 3
    petiole_sides: int = 4
    lamina_length: float = 0.08
    size_var: float = 0.15
    down_angle: float = 55.0
    down_var: float = 10.0
    roll_var: float = 15.0  # scatter about the spiral's golden angle, degrees
    droop: float = 30.0
    turn_var: float = 25.0  # scatter of the blade's turn about its petiole from facing up, degrees


@dataclass(frozen=True)
class LaminaSpec:
    """A species outline (right half, base to tip) and its serration."""

    shape: str = "ovate"
    outline: tuple = ((0.0, 0.0), (0.2, 0.3), (0.15, 0.7), (0.0, 1.0))
    samples: int = 40
    teeth: int = 0
    tooth_depth: float = 0.0
    curl: float = 0.0


@dataclass(frozen=True)
class GrassSpec:
    """A patch of grass blades, each a root object of ``segments`` segments.

    The patch is a rectangle or an ellipse (``shape``) ``size`` metres across. Over the outer
    ``edge`` of its radius the blades thin out to none and shorten to ``edge_height`` of their
    height; ``wobble`` makes a round patch's outline irregular (relative radius change).
    """

    count: int = 0
    shape: str = "rect"  # rect | round
    size: tuple[float, float] = (10.0, 10.0)
    edge: float = 0.0
    edge_height: float = 1.0
    wobble: float = 0.0
    height: tuple[float, float] = (0.3, 0.6)
    width: float = 0.012
    segments: int = 3
    bend: float = 25.0


@dataclass(frozen=True)
class BeamSpec:
    """One curved beam alone (the paper's pull-and-release study, Figs. 3–4)."""

    length: float = 2.0
    segments: int = 10
    diameter: tuple[float, float] = (0.06, 0.02)
    curvature: float = 20.0


@dataclass(frozen=True)
class CrownSpec:
    """An ellipsoidal envelope the branches are pruned to (Weber & Penn's pruning).

    The ellipsoid spans heights ``height`` (metres) and has the horizontal ``radius``; it is
    centred over the trunk's top. A branch (level 2 and up) whose tip would leave it is
    shortened until the tip lies on it, to no less than ``min_scale`` of its length; its
    children still grow in proportion to its unpruned length, so pruning does not compound
    from level to level. A radius of 0 leaves the branches as grown. Presets keep ``min_scale``
    at 0.3 or more: stubs a few centimetres long, as thick as their parent's tip, make the load
    path's oscillators diverge.
    """

    height: tuple[float, float] = (0.0, 0.0)
    radius: float = 0.0
    min_scale: float = 0.5


@dataclass(frozen=True)
class TreeSpec:
    """Everything a preset says about the shape of a tree."""

    name: str
    type: str = "tree"  # tree | grass | beam
    seed: int = 0
    levels: tuple[LevelSpec, ...] = ()
    crown: CrownSpec = field(default_factory=CrownSpec)
    leaves: LeafSpec = field(default_factory=LeafSpec)
    lamina: LaminaSpec | None = None
    grass: GrassSpec = field(default_factory=GrassSpec)
    beam: BeamSpec = field(default_factory=BeamSpec)
    physics: PhysicsParams = field(default_factory=PhysicsParams)
    source: str = ""
    bark: Bark = field(default_factory=Bark)


# ---------------------------------------------------------------------------- geometry helpers
def rotate(v: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rodrigues rotation of vectors ``v`` about unit ``axis`` by ``angle`` radians (broadcasts)."""
    v, axis = np.asarray(v, float), np.asarray(axis, float)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    return v * c + np.cross(axis, v) * s + axis * np.sum(axis * v, axis=-1, keepdims=True) * (1 - c)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def bent_polyline(base, direction, length, segments, curvature, gravity, bend_axis) -> np.ndarray:
    """Points of a branch: ``segments`` equal segments whose direction turns progressively by
    ``curvature`` degrees about ``bend_axis`` and droops toward the ground by ``gravity`` degrees.

    All inputs broadcast over a leading axis: base, direction, bend_axis (K, 3); length,
    curvature, gravity (K,). Returns (K, segments + 1, 3).
    """
    k = np.arange(segments, dtype=float)[None, :] + 0.5
    frac = k / segments
    d = rotate(direction[:, None, :], bend_axis[:, None, :], np.radians(curvature)[:, None] * frac)
    # Gravity: turn toward -y about the horizontal axis perpendicular to the direction.
    side = np.cross(d, UP)
    side_n = np.linalg.norm(side, axis=-1, keepdims=True)
    side = np.where(side_n > 1e-6, side / np.maximum(side_n, 1e-12), perpendicular(d))
    d = rotate(d, side, -np.radians(gravity)[:, None] * frac)
    steps = d * (length / segments)[:, None, None]
    return np.concatenate([base[:, None, :], base[:, None, :] + np.cumsum(steps, axis=1)], axis=1)


def _exact_split(total: int, weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Split an integer ``total`` over slots in proportion to ``weights`` (largest remainder,
    ties broken by the seeded ``rng``)."""
    if len(weights) == 0 or total <= 0:
        return np.zeros(len(weights), dtype=np.int64)
    share = total * weights / weights.sum()
    base = np.floor(share).astype(np.int64)
    rest = total - int(base.sum())
    order = np.lexsort((rng.random(len(share)), -(share - base)))
    base[order[:rest]] += 1
    return base


# ---------------------------------------------------------------------------- trees
def _prune(pts: np.ndarray, centre: np.ndarray, radii: np.ndarray, min_scale: float) -> np.ndarray:
    """Scale branches (K, n, 3) about their bases so each tip stays inside the ellipsoid.

    A branch's points grow linearly with its length, so the tip at scale s is base + s·(tip −
    base); in units of the radii, |p + s·u|² = 1 is a quadratic in s whose positive root is
    where the tip meets the envelope.
    """
    base = pts[:, :1]
    p = (base[:, 0] - centre) / radii
    u = (pts[:, -1] - base[:, 0]) / radii
    a, b, c = np.sum(u * u, axis=1), np.sum(p * u, axis=1), np.sum(p * p, axis=1) - 1
    root = (-b + np.sqrt(np.maximum(b * b - a * c, 0.0))) / np.maximum(a, 1e-30)
    scale = np.clip(np.where(c < 0, root, 0.0), min_scale, 1.0)
    return base + scale[:, None, None] * (pts - base)


def _branches(spec: TreeSpec, rng: np.random.Generator) -> list[ObjectSpec]:
    trunk = spec.levels[0]
    lean = np.radians(trunk.lean)
    az = rng.uniform(0, 2 * np.pi)
    d0 = np.array([np.sin(lean) * np.cos(az), np.cos(lean), np.sin(lean) * np.sin(az)])
    bend_axis = _unit(np.cross(d0, [np.cos(az + 1.3), 0.0, np.sin(az + 1.3)]))
    pts = bent_polyline(
        np.zeros((1, 3)), d0[None], np.array([trunk.length]), trunk.segments,
        np.array([trunk.curvature]), np.array([trunk.gravity]), bend_axis[None],
    )[0]
    diam = trunk.diameter * (1 - trunk.taper * np.linspace(0, 1, trunk.segments + 1))
    specs = [ObjectSpec(pts, diam, "branch", 1)]
    lengths = [trunk.length]
    crown = spec.crown
    if crown.radius > 0:
        lo, hi = crown.height
        centre = np.array([pts[-1, 0], 0.5 * (lo + hi), pts[-1, 2]])
        radii = np.array([crown.radius, 0.5 * (hi - lo), crown.radius])
    current = [0]
    for lv, child in enumerate(spec.levels[1:], start=2):
        if not current:
            break
        total = int(round(child.count * len(current)))
        per_parent = _exact_split(total, np.ones(len(current)), rng)
        nxt = []
        for p, n_children in zip(current, per_parent):
            if n_children == 0:
                continue
            parent = specs[p]
            n_seg = len(parent.points) - 1
            lo = max(1, int(np.ceil(child.attach[0] * n_seg - 1e-9)))
            hi = max(lo, int(np.floor(child.attach[1] * n_seg + 1e-9)))
            nodes = np.arange(lo, hi + 1)
            # Spread siblings evenly over the allowed nodes; a single child goes to the last one.
            first = 0 if n_children > 1 else len(nodes) - 1
            at = nodes[np.round(np.linspace(first, len(nodes) - 1, n_children)).astype(int)]
            axis_dir = np.diff(parent.points, axis=0)[np.minimum(at, n_seg) - 1]
            axis_dir = _unit(axis_dir)
            roll0 = rng.uniform(0, 360)
            roll = np.radians(roll0 + child.roll * np.arange(n_children) + rng.normal(0, child.roll_var, n_children))
            down = np.radians(child.down_angle + rng.normal(0, child.down_var, n_children))
            perp = perpendicular(axis_dir)
            side = rotate(perp, axis_dir, roll)
            d = rotate(axis_dir, _unit(np.cross(axis_dir, side)), down)
            d = _unit(d + child.up * (UP - d))
            length = lengths[p] * child.length * np.clip(1 + rng.normal(0, child.length_var, n_children), 0.4, 1.6)
            length *= 1 - child.cone * (at / n_seg - child.attach[0]) / max(1 - child.attach[0], 1e-9)
            bend_axis = _unit(np.cross(d, side) + 1e-9 * perpendicular(d))
            pts = bent_polyline(
                parent.points[at], d, length, child.segments,
                np.full(n_children, child.curvature), np.full(n_children, child.gravity), bend_axis,
            )
            grown = length  # children scale with the length a branch grew to, before pruning
            if crown.radius > 0:
                pts = _prune(pts, centre, radii, crown.min_scale)
                length = np.sum(np.linalg.norm(np.diff(pts, axis=1), axis=2), axis=1)
            d_base = parent.diameters[at] * min(child.diameter, 1.0)
            on_tip = at == n_seg
            if on_tip.any():
                # da Vinci's rule (the pipe model): the children on the tip share its cross-section
                # in proportion to their length, so their areas add up to the parent's.
                d_base[on_tip] = parent.diameters[-1] * np.sqrt(length[on_tip] / length[on_tip].sum())
            shape = 1 - child.taper * np.linspace(0, 1, child.segments + 1)
            for k in range(n_children):
                specs.append(ObjectSpec(pts[k], d_base[k] * shape, "branch", lv, parent=p, attach=int(at[k])))
                lengths.append(float(grown[k]))
                nxt.append(len(specs) - 1)
        current = nxt
    return specs


def _leaf_slots(lf: LeafSpec, branches: list[ObjectSpec]) -> tuple[np.ndarray, ...]:
    """The nodes that bear leaves: (branch, node, length of the segment below, free tip?)."""
    grown_on = {(s.parent, s.attach) for s in branches if s.parent >= 0}
    rows = []
    for b, s in enumerate(branches):
        if s.level in lf.levels:
            lo, hi = lf.attach
        elif s.level == 1 and lf.leader > 0:
            lo, hi = 1 - lf.leader, 1.0
        else:
            continue
        seg = np.linalg.norm(np.diff(s.points, axis=0), axis=1)
        frac = np.cumsum(seg) / seg.sum()  # of nodes 1..n along the branch
        for j in np.flatnonzero((frac >= lo - 1e-9) & (frac <= hi + 1e-9)) + 1:
            rows.append((b, j, seg[j - 1], j == len(seg) and (b, j) not in grown_on))
    if not rows:
        raise ValueError(f"key 'leaves.levels': {list(lf.levels)} names no level that has branches "
                         f"with nodes in leaves.attach {list(lf.attach)}")
    b, j, served, free = (np.array(c) for c in zip(*rows))
    return b.astype(np.int64), j.astype(np.int64), served.astype(float), free.astype(bool)


def _leaves(spec: TreeSpec, branches: list[ObjectSpec], rng: np.random.Generator) -> list[ObjectSpec]:
    lf = spec.leaves
    if lf.count <= 0:
        return []
    return place_leaves(lf, branches, _leaf_slots(lf, branches), rng)


def place_leaves(lf: LeafSpec, branches: list[ObjectSpec], slots: tuple[np.ndarray, ...],
                 rng: np.random.Generator) -> list[ObjectSpec]:
    """Leaves of ``lf`` (``lf.count`` of them) on the given branch nodes.

    Parameters
    ----------
    lf : LeafSpec
        Count, tufts, petiole and lamina sizes, angles.
    branches : list of ObjectSpec
        The tree's branches (leaves refer to them by index).
    slots : tuple of arrays
        ``(branch, node, length of the segment below, free tip?)`` per leaf-bearing node, ordered
        by branch then node: leaves are spread over them in proportion to the length they serve.
    rng : numpy.random.Generator

    Returns
    -------
    list of ObjectSpec
        One petiole object per leaf, one level below its branch.
    """
    slot_b, slot_j, served, free = slots
    # So many leaves per metre of twig, plus the tufts at the free tips.
    n_tuft = int(round(lf.tip_share * lf.count)) if free.any() else 0
    per_slot = _exact_split(lf.count - n_tuft, served, rng) + _exact_split(n_tuft, free.astype(float), rng)
    owner = np.repeat(np.arange(len(slot_b)), per_slot)
    b_idx, j_idx = slot_b[owner], slot_j[owner]
    n = len(owner)
    # Spiral phyllotaxis along each branch: the golden angle from one leaf to the next.
    first = np.searchsorted(b_idx, b_idx)  # slots (and so leaves) are ordered by branch, then node
    rank = np.arange(n) - first
    phase = rng.uniform(0, 360, len(branches))[b_idx]
    roll = np.radians(phase + GOLDEN_ANGLE * rank + rng.normal(0, lf.roll_var, n))
    base = np.array([branches[b].points[j] for b, j in zip(b_idx, j_idx)])
    axis_dir = _unit(np.array([branches[b].points[j] - branches[b].points[j - 1] for b, j in zip(b_idx, j_idx)]))
    side = rotate(perpendicular(axis_dir), axis_dir, roll)
    # Leaves along a twig stand out at down_angle; a tip's tuft opens from tip_angle to it.
    down = np.where(free[owner], rng.uniform(lf.tip_angle, lf.down_angle, n), lf.down_angle)
    down = np.radians(down + rng.normal(0, lf.down_var, n))
    d = rotate(axis_dir, _unit(np.cross(axis_dir, side)), down)
    scale = np.clip(1 + rng.normal(0, lf.size_var, n), 0.6, 1.4)
    bend_axis = _unit(np.cross(d, side) + 1e-9 * perpendicular(d))
    pts = bent_polyline(
        base, d, lf.petiole_length * scale, lf.petiole_segments,
        rng.normal(0, 10, n), np.full(n, lf.droop), bend_axis,
    )
    tip_dir = _unit(pts[:, -1] - pts[:, -2])
    # Lamina normal: as close to "up" as the petiole allows, turned a little at random.
    w = UP - tip_dir * tip_dir[:, 1:2]
    w = np.where(np.linalg.norm(w, axis=1, keepdims=True) > 1e-3, w, perpendicular(tip_dir))
    w = rotate(_unit(w), tip_dir, rng.normal(0, np.radians(lf.turn_var), n))
    # A petiole is never thicker than the twig it grows from.
    twig = np.array([branches[b].diameters[j] for b, j in zip(b_idx, j_idx)])
    base_d = np.minimum(lf.petiole_diameter * scale, twig)
    taper = np.linspace(1.0, 0.7, lf.petiole_segments + 1)
    levels = np.array([branches[b].level + 1 for b in b_idx])
    return [
        ObjectSpec(pts[k], base_d[k] * taper, "leaf", int(levels[k]), parent=int(b_idx[k]), attach=int(j_idx[k]),
                   w=w[k], lamina_length=float(lf.lamina_length * scale[k]))
        for k in range(n)
    ]


def _fade(rho: np.ndarray, edge: float) -> np.ndarray:
    """1 inside the patch, easing (smoothstep) to 0 over the outer ``edge`` of its radius."""
    if edge <= 0:
        return np.ones_like(rho)
    t = np.clip((1 - rho) / edge, 0.0, 1.0)
    return t * t * (3 - 2 * t)


def _sample(pdf: np.ndarray, grid: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Inverse-CDF samples of a density tabulated on ``grid``, at uniform numbers ``u``."""
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (pdf[1:] + pdf[:-1]) * np.diff(grid))])
    return np.interp(u, cdf / cdf[-1], grid)


def _patch(g: GrassSpec, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Blade roots (n, 2) in the ground plane and each one's relative radius in the patch.

    The relative radius rho (0 at the centre, 1 at the outline) is drawn with density
    rho * fade(rho), which is uniform per square metre inside the patch and thins out over its
    edge; a rectangle measures rho as the larger of |x| and |z| (relative), an ellipse as the
    distance, its outline pushed in and out by a seeded ``wobble``.
    """
    grid = np.linspace(0.0, 1.0, 1025)
    rho = _sample(grid * _fade(grid, g.edge), grid, rng.random(n))
    half = np.array(g.size) / 2
    if g.shape == "round":
        k = np.arange(2, 6)
        amp, phase = rng.uniform(0.3, 1.0, len(k)) / k, rng.uniform(0, 2 * np.pi, len(k))
        ring = np.linspace(0.0, 2 * np.pi, 1025)
        wave = np.cos(np.multiply.outer(ring, k) + phase) @ amp
        outline = 1 - g.wobble * (wave.max() - wave) / np.ptp(wave)  # relative radius, in [1 - wobble, 1]
        theta = _sample(outline**2, ring, rng.random(n))  # the area per angle grows as r²
        xz = (rho * np.interp(theta, ring, outline))[:, None] * np.column_stack([np.cos(theta), np.sin(theta)])
    else:  # a point on the rectangle's outline scaled by rho: uniform along it
        t, side = rng.uniform(-1.0, 1.0, n), rng.integers(0, 4, n)
        sign = np.where(side % 2 == 0, 1.0, -1.0)
        xz = rho[:, None] * np.where((side < 2)[:, None], np.column_stack([sign, t]), np.column_stack([t, sign]))
    return xz * half, rho


def _grass(spec: TreeSpec, rng: np.random.Generator) -> list[ObjectSpec]:
    g = spec.grass
    n = g.count
    xz, rho = _patch(g, n, rng)
    base = np.column_stack([xz[:, 0], np.zeros(n), xz[:, 1]])
    lean = np.radians(rng.uniform(0, 15, n))
    az = rng.uniform(0, 2 * np.pi, n)
    d = np.column_stack([np.sin(lean) * np.cos(az), np.cos(lean), np.sin(lean) * np.sin(az)])
    face = np.column_stack([np.cos(az + 0.5 * np.pi), np.zeros(n), np.sin(az + 0.5 * np.pi)])
    bend_axis = _unit(np.cross(d, np.column_stack([np.cos(az), np.zeros(n), np.sin(az)])) + 1e-9 * face)
    height = rng.uniform(*g.height, n) * (g.edge_height + (1 - g.edge_height) * _fade(rho, g.edge))
    pts = bent_polyline(base, d, height, g.segments, rng.uniform(0.3, 1.0, n) * g.bend, np.zeros(n), bend_axis)
    width = g.width * np.linspace(1.0, 0.45, g.segments + 1)
    normal = _unit(np.cross(pts[:, 1] - pts[:, 0], face))
    return [ObjectSpec(pts[k], width * rng.uniform(0.8, 1.2), "blade", 1, w=normal[k]) for k in range(n)]


def _beam(spec: TreeSpec) -> list[ObjectSpec]:
    b = spec.beam
    pts = bent_polyline(
        np.zeros((1, 3)), UP[None], np.array([b.length]), b.segments,
        np.array([b.curvature]), np.zeros(1), np.array([[0.0, 0.0, 1.0]]),
    )[0]
    return [ObjectSpec(pts, np.linspace(b.diameter[0], b.diameter[1], b.segments + 1), "branch", 1)]


def generate(spec: TreeSpec) -> Tree:
    """Build the tree a spec describes; deterministic for a given spec and seed."""
    rng = np.random.default_rng(spec.seed)
    lamina = None
    if spec.type == "grass":
        specs = _grass(spec, rng)
    elif spec.type == "beam":
        specs = _beam(spec)
    else:
        specs = _branches(spec, rng)
        specs += _leaves(spec, specs, rng)
        if spec.lamina is not None and spec.leaves.count > 0:
            la = spec.lamina
            lamina = make_lamina(la.shape, la.outline, la.samples, la.teeth, la.tooth_depth, la.curl)
    return assemble(
        specs,
        name=spec.name,
        lamina=lamina,
        petiole_sides=spec.leaves.petiole_sides,
        winter_leaves=spec.leaves.winter_count if spec.leaves.count else 0,
        physics=spec.physics,
        seed=spec.seed,
        source=spec.source,
        bark=spec.bark,
    )
