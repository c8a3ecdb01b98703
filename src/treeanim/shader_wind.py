"""Shader wind for engines: a static mesh (the glTF one, leaves as cards:
:func:`treeanim.compact.card_mesh`), its vertices' branch hierarchy and each branch's physical
parameters, for a vertex shader to sway it (``shaders/engine_wind.glsl``, the reference;
``examples/shader_wind/index.html`` runs it in three.js).

Each vertex hangs from up to :data:`LEVELS` levels of the branches it hangs from: the trunk and the
three innermost (its own object, its parent, its grandparent; a leaf is its own level). These
depend on the vertex's object only, so the file stores them once per object, in a table, and
each vertex carries its object's index (attribute ``_OBJECT``, a float) besides its position,
normal and colour. The table (:func:`object_rows`, laid out as a float texture by
:func:`texture`) is an accessor of RGBA float texels named by the mesh's
``extras.treeanim_wind.table`` (``accessor``, ``width``, ``height``); an object's entry is
:data:`ROWS` texels: per level, the pivot (the branch's base at rest, xyz; its sway frequency in
Hz, w; 0 = no such level), then per level the axis (the branch's rest direction, xyz; its
compliance, w: the mean bend in rad is compliance·U^n in a wind of U m/s at the canopy top),
then the damping ratio of each level; the exponent n is ``extras.treeanim_wind.exponent``.
All come from the simulation of the tree (docs/design.md §16):

- **compliance** and **exponent**: the mean bends of the branches against their parents in
  steady winds of :data:`CALIBRATION_WINDS` m/s along x. Drag grows as U² on rigid wood and
  slower where leaves reconfigure (Vogel's exponent), so the tree's bends grow as U^n, n fitted
  to their sums at the two speeds; a branch's compliance is its bends' geometric mean over
  U^n's;
- **frequency** and **damping**: the wind then stops, and every branch swings back and rings
  down: its frequency is the peak of its bend's spectrum, its damping ratio the decay of the
  swing's RMS between the two halves of the record (ζ = ln(r)/(2πfΔt)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import scripted
from .compact import card_mesh, runs
from .export import primitives, skeleton, skin, surface
from .model.tree import Tree
from .physics.simulation import Simulation
from .physics.wind.field import WindField
from .render.mesh import TreeMesh

__all__ = ["LEVELS", "CALIBRATION_WINDS", "BranchTable", "branch_table", "level_chains", "level_compliance",
           "object_rows", "texture", "build_shader_gltf", "build_instanced_gltf"]

#: Levels of branches a vertex carries (Unreal's Pivot Painter and SpeedTree use 3–4).
LEVELS = 4
#: The steady winds (m/s at the canopy top) the branches' bends are measured in: a breeze and a gale.
CALIBRATION_WINDS = (5.0, 15.0)
#: Seconds each steady wind blows (the last half measured) and the ring-down after the last stops.
SETTLE, RING = 5.0, 6.0
#: The rate the calibration run is stepped at (frames per second): fine enough that the implicit
#: step adds no damping of its own to a leaf's 10–15 Hz (at 1/60 s it doubles a beam's ζ). The
#: ring-down is recorded at half this rate (float32: 0.1 GB for a 40,000-object scan).
RATE = 240.0
#: Rows of an object's entry in the table (4 pivots, 4 axes, the damping ratios) and the most
#: objects a row band of the table's texture holds.
ROWS, TABLE_WIDTH = 2 * LEVELS + 1, 1024


@dataclass(frozen=True)
class BranchTable:
    """Per object: its base, rest direction and sway parameters (see the module docstring)."""

    pivot: np.ndarray       # (M, 3)
    axis: np.ndarray        # (M, 3) unit
    frequency: np.ndarray   # (M,) Hz
    damping: np.ndarray     # (M,) ζ
    compliance: np.ndarray  # (M,) rad per (m/s)^exponent
    exponent: float         # the bends grow as U^exponent


def _bend(tree: Tree, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """(M,) each object's bend: the turn of its chord (base to tip) from rest, in its parent's
    frame at the attachment, about the z axis (across a wind along x; rad, signed). The whole
    branch turning about its base is what the shader moves."""
    first, last = tree.object_start, tree.object_start + tree.object_count - 1
    att = tree.attach_node
    P = np.where(att[:, None, None] >= 0, rotations[np.maximum(att, 0)], np.eye(3))
    rest = tree.rest_positions[last] - tree.rest_positions[first]
    now = np.einsum("mki,mk->mi", P, positions[last] - positions[first])  # Pᵀ·chord
    rest /= np.maximum(np.linalg.norm(rest, axis=1, keepdims=True), 1e-300)
    now /= np.maximum(np.linalg.norm(now, axis=1, keepdims=True), 1e-300)
    return np.arcsin(np.clip(rest[:, 0] * now[:, 1] - rest[:, 1] * now[:, 0], -1.0, 1.0))


def branch_table(tree: Tree, season: float = 0.0) -> BranchTable:
    """Measure every object's sway parameters from the simulation of ``tree`` (module docstring).

    Parameters
    ----------
    tree : Tree
    season : float
        Leaves present (0 = summer … 1 = winter).

    Returns
    -------
    BranchTable
    """
    u1, u2 = CALIBRATION_WINDS
    sim = Simulation(tree, season=season)
    settle, ring = int(SETTLE * RATE), int(RING * RATE)
    lean = {u2: 0.0, u1: 0.0}  # the mean bends over each steady wind's last half
    swing = np.empty((ring // 2, tree.n_objects), np.float32)  # the ring-down, every other step
    for k in scripted.frames(sim, 2 * settle + ring, RATE, []):
        if k in (0, settle):  # the gale, then the breeze (from the gale's lean, so less to settle)
            sim.wind = WindField(speed=u2 if k == 0 else u1, turbulence=0.0, gust_strength=0.0)
        elif k == 2 * settle:
            sim.wind = None  # calm: every branch swings back and rings down
        if k < 2 * settle and k % settle >= settle // 2:
            lean[u2 if k < settle else u1] += _bend(tree, sim.positions, sim.rotations) / (settle - settle // 2)
        elif k >= 2 * settle and (k - 2 * settle) % 2 == 0 and (k - 2 * settle) // 2 < len(swing):
            swing[(k - 2 * settle) // 2] = _bend(tree, sim.positions, sim.rotations)
    b1, b2 = np.abs(lean[u1]), np.abs(lean[u2])
    exponent = float(np.log(b2.sum() / max(b1.sum(), 1e-300)) / np.log(u2 / u1))
    compliance = np.sqrt(b1 * b2) / (u1 * u2) ** (0.5 * exponent)
    rate = RATE / 2
    swing = swing - swing[-len(swing) // 4:].mean(axis=0)
    pad = 8 * len(swing)  # zero-padded: the peak between the bins of a few seconds' record
    spectrum = np.abs(np.fft.rfft(swing * np.hanning(len(swing))[:, None], n=pad, axis=0))
    freqs = np.fft.rfftfreq(pad, 1.0 / rate)
    frequency = freqs[1:][np.argmax(spectrum[1:], axis=0)]
    half = len(swing) // 2
    r = np.sqrt(np.mean(swing[:half] ** 2, axis=0) / np.maximum(np.mean(swing[half:] ** 2, axis=0), 1e-30))
    damping = np.log(np.maximum(r, 1.0)) / (2.0 * np.pi * np.maximum(frequency, 1e-6) * half / rate)

    X = tree.rest_positions
    base = X[tree.object_start]
    tip = X[tree.object_start + tree.object_count - 1]
    axis = tip - base
    axis /= np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-12)
    return BranchTable(pivot=base, axis=axis, frequency=frequency, damping=np.clip(damping, 0.01, 2.0),
                       compliance=compliance, exponent=exponent)


def level_chains(tree: Tree) -> tuple[np.ndarray, np.ndarray]:
    """The branches each object's vertices sway with, trunk first.

    Returns
    -------
    levels : (M, LEVELS) int
        The objects whose frequency, damping and axis each level takes: the root and the three
        innermost of the object's chain (−1 where the chain is shorter).
    pivots : (M, LEVELS) int
        The object whose base is each level's pivot: the level's own, except where the chain
        skips branches between the root and level 1: that level then swings them and its
        object as one piece about the first skipped branch's base.
    """
    levels = np.full((tree.n_objects, LEVELS), -1, np.int64)
    pivots = levels.copy()
    for o in range(tree.n_objects):
        chain = [o]
        while tree.parent[chain[-1]] >= 0:
            chain.append(int(tree.parent[chain[-1]]))
        chain.reverse()
        kept = chain if len(chain) <= LEVELS else chain[:1] + chain[-(LEVELS - 1):]
        levels[o, :len(kept)] = kept
        pivots[o, :len(kept)] = kept
        if len(chain) > LEVELS:
            pivots[o, 1] = chain[1]
    return levels, pivots


def level_compliance(tree: Tree, table: BranchTable, levels: np.ndarray) -> np.ndarray:
    """(M, LEVELS) each level's compliance: the bends of every branch from the level above it
    (exclusive) to its own (inclusive) added up, so a level standing for skipped branches
    bends as much as they do together (small bends about nearly parallel axes add)."""
    cum = table.compliance.astype(float).copy()
    for o in range(tree.n_objects):  # parents come first
        if tree.parent[o] >= 0:
            cum[o] += cum[tree.parent[o]]
    on = levels >= 0
    c = np.where(on, cum[np.maximum(levels, 0)], 0.0)
    c[:, 1:] -= np.where(on[:, 1:], c[:, :-1], 0.0)
    return c


def object_rows(tree: Tree, table: BranchTable) -> np.ndarray:
    """(M, ROWS, 4) float32 each object's shader-wind entry: its levels' pivots (xyz, and the
    level's frequency in w; 0 = no such level), rest axes (xyz, and the level's compliance in
    w), and the levels' damping ratios; what ``shaders/engine_wind.glsl`` reads for a vertex of
    that object (module docstring)."""
    levels, pivots = level_chains(tree)
    on = levels >= 0
    o = np.maximum(levels, 0)
    rows = np.zeros((tree.n_objects, ROWS, 4), np.float32)
    rows[:, :LEVELS, :3] = table.pivot[np.maximum(pivots, 0)]
    rows[:, :LEVELS, 3] = np.where(on, table.frequency[o], 0.0)
    rows[:, LEVELS:2 * LEVELS, :3] = table.axis[o]
    rows[:, LEVELS:2 * LEVELS, 3] = level_compliance(tree, table, levels)
    rows[:, 2 * LEVELS] = np.where(on, table.damping[o], 0.0)
    return rows


def texture(rows: np.ndarray, width: int = TABLE_WIDTH) -> np.ndarray:
    """(H, W, 4) the objects' entries (M, ROWS, 4) as a float texture: object o's row r at texel
    (o mod W, ROWS·⌊o / W⌋ + r), W = min(M, ``width``): bands of ``width`` objects, so that at
    1,024 a texture stays within the 2,048 texels a side WebGL 2 guarantees up to 232,448
    objects."""
    M = len(rows)
    W = min(M, width)
    bands = -(-M // W)
    tex = np.zeros((bands * W, ROWS, 4), np.float32)
    tex[:M] = rows
    return tex.reshape(bands, W, ROWS, 4).transpose(0, 2, 1, 3).reshape(bands * ROWS, W, 4)


def _wind_mesh(doc, blob, tree: Tree, table: BranchTable, season: float, mesh: TreeMesh | None = None) -> int:
    """Add ``tree``'s static mesh with its shader-wind table and vertex object indices to
    ``doc`` (module docstring); its mesh index."""
    import pygltflib as gl

    mesh = mesh if mesh is not None else card_mesh(tree)
    present = tree.leaves_present(season)
    keep_tris, used, pos, _, _ = skin(tree, mesh, skeleton(tree, present), present)
    nrm, col = surface(tree, mesh, used, season)
    tex = texture(object_rows(tree, table))
    columns = {"POSITION": (pos, gl.VEC3, gl.FLOAT, None), "NORMAL": (nrm, gl.VEC3, gl.FLOAT, None),
               "COLOR_0": (col, gl.VEC4, gl.UNSIGNED_BYTE, True),
               "_OBJECT": (mesh.object[used].astype(np.float32), gl.SCALAR, gl.FLOAT, None)}
    entries = blob.accessor(tex.reshape(-1, 4), gl.VEC4, gl.FLOAT)
    index = (np.cumsum(used) - 1)[mesh.indices[keep_tris]]
    wind = {"levels": LEVELS, "exponent": round(table.exponent, 4), "calibration_winds": list(CALIBRATION_WINDS),
            "table": {"accessor": entries, "width": tex.shape[1], "height": tex.shape[0], "rows": ROWS},
            "shader": "shaders/engine_wind.glsl"}
    try:
        runs(index, 65535)
        short = True
    except ValueError:  # a scene's trees interleave their vertices (objects sort by level): 32-bit indices
        short = False
    doc.meshes.append(gl.Mesh(name=tree.name, primitives=primitives(doc, blob, tree, mesh, used, index, columns, short),
                              extras={"treeanim_wind": wind}))
    return len(doc.meshes) - 1


def _document():
    import pygltflib as gl

    from .export import _Blob

    doc = gl.GLTF2(asset=gl.Asset(version="2.0", generator="treeanim (shader wind)"))
    return doc, _Blob(doc)


def _finish(doc, blob, name: str):
    import pygltflib as gl

    doc.scenes.append(gl.Scene(name=name, nodes=list(range(len(doc.nodes)))))
    doc.scene = 0
    data = blob.bytes()
    doc.buffers.append(gl.Buffer(byteLength=len(data)))
    return doc, data


def build_shader_gltf(tree: Tree, table: BranchTable, season: float = 0.0, mesh: TreeMesh | None = None):
    """The static glTF of ``tree`` with the shader-wind table and each vertex's object index
    (module docstring).

    Returns
    -------
    (pygltflib.GLTF2, bytes)
        The document and its buffer, for :func:`treeanim.export.write_gltf`.
    """
    import pygltflib as gl

    doc, blob = _document()
    doc.nodes.append(gl.Node(name=tree.name, mesh=_wind_mesh(doc, blob, tree, table, season, mesh)))
    return _finish(doc, blob, tree.name)


def build_instanced_gltf(name: str, templates: list[tuple[Tree, BranchTable]], placements: list[list],
                         season: float = 0.0):
    """A scene as instances of template trees: each template's static shader-wind mesh (as
    :func:`build_shader_gltf` writes it, at the origin) in a node whose
    ``EXT_mesh_gpu_instancing`` places it at every tree of the scene that takes it.

    Parameters
    ----------
    name : str
        The scene's name.
    templates : list of (Tree, BranchTable)
        The trees as generated (at the origin, heading 0, scale 1) and their measured tables.
    placements : list of lists of Placement
        Per template, the scene's trees that take it (their position, heading and scale).
    season : float

    Returns
    -------
    (pygltflib.GLTF2, bytes)
    """
    import pygltflib as gl

    doc, blob = _document()
    for (tree, table), where in zip(templates, placements):
        half = np.radians([p.heading for p in where]) / 2  # the turn about +y (scene.heading_matrix)
        rotation = np.zeros((len(where), 4), np.float32)
        rotation[:, 1], rotation[:, 3] = np.sin(half), np.cos(half)
        columns = {"TRANSLATION": np.array([p.position for p in where], np.float32), "ROTATION": rotation,
                   "SCALE": np.repeat(np.array([[p.scale] for p in where], np.float32), 3, axis=1)}
        attributes = {k: blob.accessor(a, gl.VEC4 if k == "ROTATION" else gl.VEC3, gl.FLOAT) for k, a in columns.items()}
        doc.nodes.append(gl.Node(name=tree.name, mesh=_wind_mesh(doc, blob, tree, table, season),
                                 extensions={"EXT_mesh_gpu_instancing": {"attributes": attributes}}))
    doc.extensionsUsed = ["EXT_mesh_gpu_instancing"]
    return _finish(doc, blob, name)
