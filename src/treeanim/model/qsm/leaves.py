"""Leaves for a scanned tree: the species table and the leaf-area rule along its twigs (``--leaves``)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ...errors import QSMError
from ..build import ObjectSpec
from ..generate import LeafSpec


@dataclass(frozen=True)
class Species:
    """Leaves added procedurally to a scanned tree (``--leaves NAME``).

    Attributes
    ----------
    preset : str
        Shipped preset whose lamina outline, leaf and petiole sizes, angles, bark and physics
        ranges the species takes.
    per_metre : float
        Leaves per metre of twig (of the model's twigs; a QSM resolves no shoot finer than
        a centimetre or two, so this counts the leaves of the unresolved shoots too).
    twig_diameter : float
        Branch segments at most this thick (m) bear leaves, and every free tip.
    wood : str
        A key of :data:`~treeanim.model.params.WOOD_TYPES`.
    """

    preset: str
    per_metre: float
    twig_diameter: float = 0.04
    wood: str = "hardwood"


#: The leaf table: one entry per species ``--leaves`` accepts.
SPECIES = {
    "cherry": Species("large_cherry", per_metre=40.0),
    "tulip_poplar": Species("tulip_poplar", per_metre=25.0),
}


#: The preset whose physics (f and ζ ranges, drag gains) and bark a leafless model takes.
DEFAULT_PRESET = "large_cherry"


#: Why leaves (``--leaves``, a scene table's ``leaves``, ``load_tree(leaves=...)``) are refused
#: for a preset or a scene: the one message, wherever it is refused.
LEAVES_FOR_QSM_ONLY = "leaves are only for TreeQSM models (.txt, .csv, .mat); a preset has its own leaves"

#: Most leaves per metre of twig ``--leaves NAME:PER_METRE`` accepts.
MAX_PER_METRE = 1000.0


def parse_leaves(leaves: str | None) -> Species | None:
    """The species of ``--leaves``: None or 'none' (leafless), ``NAME`` (a key of
    :data:`SPECIES`) or ``NAME:PER_METRE`` (its leaves per metre of twig overridden).

    Raises
    ------
    QSMError
        An unknown species or a count that is not a number in (0, :data:`MAX_PER_METRE`].
    """
    if leaves is None or leaves == "none":
        return None
    name, _, count = str(leaves).partition(":")
    if name not in SPECIES:
        raise QSMError(f"--leaves {leaves!r}: unknown species; expected none or one of {', '.join(SPECIES)} "
                       "(optionally NAME:LEAVES_PER_METRE)")
    species = SPECIES[name]
    if count:
        try:
            per_metre = float(count)
        except ValueError:
            per_metre = float("nan")
        if not 0 < per_metre <= MAX_PER_METRE:
            raise QSMError(f"--leaves {leaves!r}: expected leaves per metre of twig in (0, {MAX_PER_METRE:g}] "
                           f"after the colon, got {count!r}")
        species = dataclasses.replace(species, per_metre=per_metre)
    return species


def _preset_spec(name: str):
    from importlib import resources

    from ..presets import read_spec

    with resources.as_file(resources.files("treeanim.presets") / f"{name}.toml") as p:
        return read_spec(p)


def _scaled_ei_max(preset, d_max: float) -> float:
    """The preset's EI_max (Eq. 10, the paper's model) scaled to this trunk as D⁴."""
    return float(min(preset.physics.ei_max * (d_max / preset.levels[0].diameter) ** 4, 1e12))


#: Longest stretch of twig (m) between leaf-bearing nodes: leaf-bearing cylinders are cut into
#: segments this long at most (straight, the same wood), so leaves spread along a twig instead
#: of bunching at cylinder joints half a metre apart.
LEAF_SPACING = 0.1


def _leaf_rule(species: Species, leaf: LeafSpec, branches: list[ObjectSpec]) -> tuple[list, LeafSpec, tuple]:
    """The branches with their leaf-bearing segments cut to :data:`LEAF_SPACING`, the leaf-bearing
    nodes (ends of segments at most ``twig_diameter`` thick, and free tips) and the species'
    leaves with a count of ``per_metre`` × the twig length they serve."""
    grown_on = {(s.parent, s.attach) for s in branches}
    cut, node_map = [], []
    for i, s in enumerate(branches):  # cut the leaf-bearing segments
        seg = np.linalg.norm(np.diff(s.points, axis=0), axis=1)
        bear = 0.5 * (s.diameters[1:] + s.diameters[:-1]) <= species.twig_diameter
        bear[-1] |= (i, len(seg)) not in grown_on
        k = np.where(bear, np.maximum(1, np.ceil(seg / LEAF_SPACING - 1e-9)).astype(int), 1)
        t = np.concatenate([np.arange(n) / n for n in k] + [[0.0]])
        a = np.append(np.repeat(np.arange(len(seg)), k), len(seg) - 1)
        t[-1] = 1.0
        pts = s.points[a] + t[:, None] * (s.points[np.minimum(a + 1, len(seg))] - s.points[a])
        dia = s.diameters[a] + t * (s.diameters[np.minimum(a + 1, len(seg))] - s.diameters[a])
        node_map.append(np.concatenate([[0], np.cumsum(k)]))
        cut.append((pts, dia, np.repeat(bear, k), np.repeat(np.arange(len(seg)) == len(seg) - 1, k)))
    out, b, j, served, free = [], [], [], [], []
    for i, (s, (pts, dia, bear, last)) in enumerate(zip(branches, cut)):
        attach = int(node_map[s.parent][s.attach]) if s.parent >= 0 else s.attach
        out.append(dataclasses.replace(s, points=pts, diameters=dia, attach=attach))
        nodes = np.flatnonzero(bear) + 1
        b.append(np.full(len(nodes), i))
        j.append(nodes)
        served.append(np.linalg.norm(pts[nodes] - pts[nodes - 1], axis=1))
        free.append((nodes == len(pts) - 1) & ((i, len(s.points) - 1) not in grown_on))
    slots = (np.concatenate(b).astype(np.int64), np.concatenate(j).astype(np.int64),
             np.concatenate(served).astype(float), np.concatenate(free).astype(bool))
    count = int(round(species.per_metre * float(slots[2].sum()) / max(1.0 - leaf.tip_share, 1e-9)))
    return out, dataclasses.replace(leaf, count=max(count, 1), levels=()), slots
