"""Seeded procedural trees in the spirit of Weber & Penn (1995).

A preset gives the trunk and, per hierarchy level, how many children each branch carries,
where along it, at what branching and roll angles, with what length and radius ratios, taper,
curvature and gravity bend. Leaves sit on the nodes of the outer levels in phyllotactic
rosettes; grass blades are scattered roots. The same spec and seed give bit-identical arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .build import ObjectSpec, assemble, perpendicular
from .lamina import make_lamina
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
    diameter: float = 0.6  # metres for the trunk, ratio to the parent's diameter at the joint
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
    """Leaves: petiole beams with a lamina, in rosettes on outer nodes."""

    count: int = 0
    winter_count: int = 0
    levels: tuple[int, ...] = ()
    petiole_length: float = 0.03
    petiole_diameter: float = 0.002
    petiole_segments: int = 3
    petiole_sides: int = 4
    lamina_length: float = 0.08
    size_var: float = 0.15
    down_angle: float = 55.0
    droop: float = 30.0


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
    """A patch of grass blades, each a root object of ``segments`` segments."""

    count: int = 0
    size: tuple[float, float] = (10.0, 10.0)
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
class TreeSpec:
    """Everything a preset says about the shape of a tree."""

    name: str
    type: str = "tree"  # tree | grass | beam
    seed: int = 0
    levels: tuple[LevelSpec, ...] = ()
    leaves: LeafSpec = field(default_factory=LeafSpec)
    lamina: LaminaSpec | None = None
    grass: GrassSpec = field(default_factory=GrassSpec)
    beam: BeamSpec = field(default_factory=BeamSpec)
    physics: PhysicsParams = field(default_factory=PhysicsParams)
    source: str = ""


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
            d_base = parent.diameters[at] * child.diameter
            shape = 1 - child.taper * np.linspace(0, 1, child.segments + 1)
            for k in range(n_children):
                specs.append(ObjectSpec(pts[k], d_base[k] * shape, "branch", lv, parent=p, attach=int(at[k])))
                lengths.append(float(length[k]))
                nxt.append(len(specs) - 1)
        current = nxt
    return specs


def _leaves(spec: TreeSpec, branches: list[ObjectSpec], rng: np.random.Generator) -> list[ObjectSpec]:
    lf = spec.leaves
    if lf.count <= 0:
        return []
    # Eligible nodes: every non-base node of a branch on the leaf levels.
    slots = [(b, j) for b, s in enumerate(branches) if s.level in lf.levels for j in range(1, len(s.points))]
    if not slots:
        raise ValueError(f"key 'leaves.levels': {list(lf.levels)} names no level that has branches")
    per_slot = _exact_split(lf.count, np.ones(len(slots)), rng)
    owner = np.repeat(np.arange(len(slots)), per_slot)
    rank_in_slot = np.concatenate([np.arange(c) for c in per_slot])
    b_idx = np.array([slots[o][0] for o in owner])
    j_idx = np.array([slots[o][1] for o in owner])
    n = len(owner)
    base = np.array([branches[b].points[j] for b, j in zip(b_idx, j_idx)])
    axis_dir = _unit(np.array([branches[b].points[j] - branches[b].points[j - 1] for b, j in zip(b_idx, j_idx)]))
    roll = np.radians(rng.uniform(0, 360, len(slots))[owner] + GOLDEN_ANGLE * rank_in_slot + rng.normal(0, 15, n))
    side = rotate(perpendicular(axis_dir), axis_dir, roll)
    down = np.radians(lf.down_angle + rng.normal(0, 10, n))
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
    w = rotate(_unit(w), tip_dir, rng.normal(0, np.radians(25), n))
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


def _grass(spec: TreeSpec, rng: np.random.Generator) -> list[ObjectSpec]:
    g = spec.grass
    n = g.count
    base = np.column_stack([
        rng.uniform(-g.size[0] / 2, g.size[0] / 2, n), np.zeros(n), rng.uniform(-g.size[1] / 2, g.size[1] / 2, n),
    ])
    lean = np.radians(rng.uniform(0, 15, n))
    az = rng.uniform(0, 2 * np.pi, n)
    d = np.column_stack([np.sin(lean) * np.cos(az), np.cos(lean), np.sin(lean) * np.sin(az)])
    face = np.column_stack([np.cos(az + 0.5 * np.pi), np.zeros(n), np.sin(az + 0.5 * np.pi)])
    bend_axis = _unit(np.cross(d, np.column_stack([np.cos(az), np.zeros(n), np.sin(az)])) + 1e-9 * face)
    height = rng.uniform(*g.height, n)
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
    )
