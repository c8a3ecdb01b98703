"""Compact glTF files (``export --precision compact``, the default): quantised attributes and
rotation keys, and each joint's keys thinned where its motion allows.

What the file stores, and what it costs in motion:

- **Positions** as normalised 16-bit integers (KHR_mesh_quantization): a vertex at x is stored
  as round(32767 x / h), h the largest |coordinate| of the mesh, and the scale h is folded
  into every joint's inverse bind matrix (the node of a skinned mesh has no transform of its
  own). A uniform scale about the origin, not a box's offset and extent: Blender's importer
  guesses the bind pose from the inverse bind matrices, drops their scale and would keep an
  offset as a shift of the whole armature. On a 12 m tree a step is 0.37 mm, the error at
  most half of it.
- **Normals** as normalised 8-bit integers (KHR_mesh_quantization): 0.45° at most.
- **Leaves** as cards (:func:`card`): 6 vertices a leaf, cut to its shape by a texture's
  alpha (:func:`leaf_texture`), where the viewer draws its outline (118 on a cherry leaf).
- **Triangle indices** as 16-bit integers: the mesh is cut into primitives of at most 65,535
  vertices (:func:`runs`), which share the vertex buffers. **Joint indices** as 8-bit
  integers where the skin has at most 256 joints (both core glTF).
- **Rotation keys** as normalised 16-bit integers (core glTF): 8 bytes a key, not 16, and
  about 0.003° off at most (half a step, 1/65534, on each component). A joint's key is its
  rotation relative to its parent's as the file plays it (:func:`encode`), so the rounding
  does not add up down the chains.
- **Fewer keys** where the motion allows: each joint keeps every s-th key, s the largest
  divisor of the clip's n frames whose interpolation (the client's slerp) stays within the
  joint's tolerance at every frame; a joint that hardly moves keeps only its first and last
  key (s = n). Joints with one stride share one time accessor. The tolerance is an angle,
  :data:`TOLERANCE` over the joint's reach (the farthest vertex it carries), so no vertex
  moves more than :data:`TOLERANCE` by one joint's keys.

The file is to stay within 1 mm of the full one everywhere: an artist sees a vertex off by a
pixel, 2.6 mm for a 10 m tree filling a 4K frame. A joint's error still moves its
descendants' pivots, so errors add up a little along a chain: :data:`TOLERANCE` is 0.5 mm a
joint. On a small cherry in wind 2 (4 s at 30 fps) 1 mm a joint gave 1.48 mm at worst and
kept 34 % of the keys, 0.5 mm gives 0.64 mm and 61 %, 0.25 mm 0.34 mm and 87 %. The error
of all of it together is measured, not bounded (:func:`error`): the mesh skinned as the file
skins it against the exact keys and positions, every vertex, at 31 frames between keys.
"""

from __future__ import annotations

import io

import numpy as np

from .loop import _conj, _mul
from .model.tree import Lamina
from .physics.compiled import njit
from .pose import _levels, _qmul, _rest, displacement, world_pose
from .render.mesh import TreeMesh, build_mesh

__all__ = ["PRECISIONS", "TOLERANCE", "TEXTURE_SIZE", "card", "card_mesh", "decode", "encode", "error", "leaf_texture",
           "leaf_uv", "positions", "reach", "report", "runs", "shorts", "strides", "unit"]

#: ``export --precision``: ``compact`` (quantised, keys thinned) or ``full`` (float32, every key).
PRECISIONS = ("compact", "full")
#: The most one joint's thinned keys may move a vertex (m).
TOLERANCE = 5e-4
#: The leaf texture's side (texels): 0.5 mm a texel along a 13 cm cherry leaf.
TEXTURE_SIZE = 256
_SHORT = 32767.0


def positions(pos: np.ndarray) -> tuple[np.ndarray, float]:
    """Positions (V, 3) as normalised shorts (V, 4) (the fourth 0: a vertex attribute's elements
    start on 4 bytes) and the scale h: a position is h × stored / 32767."""
    h = float(np.max(np.abs(pos))) or 1.0
    q = np.zeros((len(pos), 4), np.int16)
    q[:, :3] = np.round(np.asarray(pos, np.float64) / h * _SHORT)
    return q, h


def unit(v: np.ndarray) -> np.ndarray:
    """Unit vectors (V, 3) as normalised bytes (V, 4), the fourth 0."""
    q = np.zeros((len(v), 4), np.int8)
    q[:, :3] = np.round(np.asarray(v, np.float64) * 127.0)
    return q


def shorts(q: np.ndarray) -> np.ndarray:
    """Unit quaternions (..., 4) as normalised shorts."""
    return np.round(np.asarray(q, np.float64) * _SHORT).astype(np.int16)


def runs(tris: np.ndarray, limit: int | None = 65535, cuts=()) -> tuple[np.ndarray, list[tuple[int, int, int, int]]]:
    """The mesh's triangles (T, 3) in primitives of at most ``limit`` vertices each (65,535:
    16-bit indices, 65,535 itself being reserved; None: no limit): consecutive ranges of the
    vertices, cut where no triangle straddles the cut, and at ``cuts`` (vertices where another
    material's begin; no triangle may straddle them).

    Returns
    -------
    order : (T,) int
        The triangles, reordered so that each primitive's are consecutive.
    runs : list of (t0, t1, v0, v1)
        Each primitive's triangles ``order[t0:t1]`` and its vertices [v0, v1).
    """
    lo, hi = tris.min(axis=1), tris.max(axis=1)
    V = int(hi.max()) + 1
    straddle = np.zeros(V + 1, np.int64)  # straddle[c] > 0: a triangle has lo < c <= hi
    np.add.at(straddle, lo + 1, 1)
    np.add.at(straddle, hi + 1, -1)
    clean = np.flatnonzero(np.cumsum(straddle) == 0)
    forced = np.union1d(np.asarray(cuts, np.int64), [V])
    out = [0]
    while out[-1] < V:
        cut = int(forced[np.searchsorted(forced, out[-1], side="right")])
        if limit is not None and cut - out[-1] > limit:
            cut = int(clean[np.searchsorted(clean, out[-1] + limit, side="right") - 1])
            if cut == out[-1]:
                raise ValueError(f"no cut of the mesh into primitives of at most {limit:,} vertices")
        out.append(cut)
    run = np.searchsorted(out, lo, side="right") - 1
    order = np.argsort(run, kind="stable")
    t = np.searchsorted(run[order], np.arange(len(out)))
    return order, [(int(t[k]), int(t[k + 1]), out[k], out[k + 1]) for k in range(len(out) - 1)]


def reach(tree, skel, pos: np.ndarray, joint: np.ndarray) -> np.ndarray:
    """(J,) for each joint, an upper bound of the distance from its pivot to the vertices it
    carries (its subtree's): the farthest corner of their bounding box (m)."""
    J = skel.count
    lo = np.full((J, 3), np.inf)
    hi = np.full((J, 3), -np.inf)
    np.minimum.at(lo, joint, pos)
    np.maximum.at(hi, joint, pos)
    for idx in reversed(_levels(skel.joint_parent)[1:]):  # children into parents, deepest first
        p = skel.joint_parent[idx]
        np.minimum.at(lo, p, lo[idx])
        np.maximum.at(hi, p, hi[idx])
    rest = _rest(tree, skel)
    far = np.maximum(np.abs(lo - rest), np.abs(hi - rest))
    return np.where(np.isfinite(far).all(axis=1), np.linalg.norm(np.where(np.isfinite(far), far, 0), axis=1), 0.0)


def _thin(keys: np.ndarray, s: int) -> np.ndarray:
    """(F, J, 4) the keys a client plays from every s-th key of ``keys`` (F, J, 4), F − 1 a
    multiple of s: a slerp between neighbouring kept keys."""
    out = np.empty(keys.shape)
    _slerps(np.ascontiguousarray(keys, np.float64), s, out)
    return out


@njit(cache=True, inline="always")
def _slerp(keys, s, f, j):
    """The key a client plays at frame f of joint j from every s-th of ``keys``: a (a⁻¹b)^u, a
    and b the kept keys around f (b's sign taken nearer a), u = (f − i s)/s (i of a); as
    ``_mul(a, _exp(u * _log(_mul(_conj(a), b))))``, a tuple."""
    i = min(f // s, (keys.shape[0] - 1) // s - 1)
    u = (f - i * s) / s
    a, b = keys[i * s, j], keys[(i + 1) * s, j]
    sign = -1.0 if a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0 else 1.0
    dx, dy, dz, dw = _qmul((-a[0], -a[1], -a[2], a[3]), (sign * b[0], sign * b[1], sign * b[2], sign * b[3]))
    if dw < 0:  # the shorter way round
        dx, dy, dz, dw = -dx, -dy, -dz, -dw
    sn = np.sqrt(dx * dx + dy * dy + dz * dz)
    k = 2.0 * np.arctan2(sn, dw) / sn if sn > 1e-12 else 2.0
    rx, ry, rz = u * dx * k, u * dy * k, u * dz * k
    angle = np.sqrt(rx * rx + ry * ry + rz * rz)
    c = np.sin(0.5 * angle) / angle if angle > 1e-12 else 0.5
    return _qmul(a, (rx * c, ry * c, rz * c, np.cos(0.5 * angle)))


@njit(cache=True)
def _slerps(keys, s, out):
    """out[f, j]: :func:`_slerp` at every frame and joint."""
    for f in range(keys.shape[0]):
        for j in range(keys.shape[1]):
            out[f, j, 0], out[f, j, 1], out[f, j, 2], out[f, j, 3] = _slerp(keys, s, f, j)


@njit(cache=True)
def _within(keys, s, cols, limit, ok):
    """ok[c]: joint cols[c]'s :func:`_slerp` stays within limit[c] radians of its key at every
    frame (the angle as :func:`treeanim.loop.angles` takes it); stops at the first that does not."""
    for c in range(len(cols)):
        j = cols[c]
        ok[c] = True
        for f in range(keys.shape[0]):
            p = _slerp(keys, s, f, j)
            q = keys[f, j]
            sign = -1.0 if p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3] < 0 else 1.0
            d2 = s2 = 0.0
            for k in range(4):
                d2 += (p[k] - sign * q[k]) ** 2
                s2 += (p[k] + sign * q[k]) ** 2
            if 4.0 * np.arctan2(np.sqrt(d2), np.sqrt(s2)) > limit[c]:
                ok[c] = False
                break


def strides(keys: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """(J,) each joint's stride: the largest divisor s of F − 1 for which every s-th of its
    keys (F, J, 4), interpolated, stays within ``limit`` (J,) radians of every key."""
    keys = np.ascontiguousarray(keys, np.float64)
    n = len(keys) - 1
    out = np.ones(keys.shape[1], np.int64)
    todo = np.ones(keys.shape[1], bool)
    for s in sorted((d for d in range(2, n + 1) if n % d == 0), reverse=True):
        cols = np.flatnonzero(todo)
        if not len(cols):
            break
        ok = np.empty(len(cols), bool)
        _within(keys, s, cols, np.ascontiguousarray(limit[cols], np.float64), ok)
        out[cols[ok]] = s
        todo[cols[ok]] = False
    return out


def decode(keys: np.ndarray, stride: np.ndarray) -> np.ndarray:
    """(F, J, 4) the rotations a client plays at every frame from the file's keys: each
    joint's every ``stride``-th of ``keys`` (F, J, 4), quantised to shorts."""
    q = shorts(keys) / _SHORT
    out = np.empty_like(q)
    for s in np.unique(stride):
        cols = np.flatnonzero(stride == s)
        out[:, cols] = _thin(q[:, cols], int(s))
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def encode(tree, skel, keys: np.ndarray, pos: np.ndarray, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The keys a compact file stores, and each joint's stride.

    A joint's key is its rotation relative to its parent's rotation *as the file plays it*
    (quantised and thinned), not as simulated, so no joint inherits its ancestors' rounding:
    each joint's world rotation is off by its own rounding and thinning only (on the 15 m tulip
    poplar, quantising each local key on its own let the errors add up along the chains to
    2.7 mm). Level by level from the root; a joint's stride (:func:`strides`) keeps within
    :data:`TOLERANCE` over its :func:`reach`.

    Parameters
    ----------
    keys : (F, J, 4) float
        The exact local rotations of ``skel``'s joints.
    pos, joints : (V, 3) float, (V, 4) int
        The skinned vertices and their joints (:func:`treeanim.export.skin`).

    Returns
    -------
    local : (F, J, 4) float64
        The keys to store (every s-th of a joint's, quantised with :func:`shorts`).
    stride : (J,) int
    """
    keys = np.asarray(keys, np.float64)
    world, _ = world_pose(tree, skel, keys)
    limit = TOLERANCE / np.maximum(reach(tree, skel, pos, joints[:, 0]), 1e-9)
    played, local = np.zeros_like(world), keys.copy()
    played[..., 3] = 1.0
    stride = np.ones(skel.count, np.int64)
    for idx in _levels(skel.joint_parent)[1:]:  # parents first: each level on its parents as played
        p = skel.joint_parent[idx]
        loc = _mul(_conj(played[:, p]), world[:, idx])
        local[:, idx] = loc = np.where(loc[..., 3:] < 0, -loc, loc)
        stride[idx] = strides(loc, limit[idx])
        played[:, idx] = _mul(played[:, p], decode(loc, stride[idx]))
    return local, stride


def error(tree, skel, keys: np.ndarray, pos: np.ndarray, joints: np.ndarray, weights: np.ndarray,
          frames: int = 31, encoded: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[float, float, int]:
    """The displacement of the mesh as the compact file skins it from the mesh skinned with the
    exact keys and positions: every vertex, at ``frames`` frames midway between evenly spread
    ones (so not all on kept keys).

    Parameters
    ----------
    tree, skel
        The tree and the skeleton the keys are for.
    keys : (F, J, 4) float
        The exact keys.
    pos, joints, weights : (V, 3), (V, 4), (V, 4)
        The skinned vertices (:func:`treeanim.export.skin`).
    frames : int
        How many frames to measure.
    encoded : (keys, stride), optional
        :func:`encode` of ``keys``, if already at hand.

    Returns
    -------
    rms, worst : float
        Over vertices and frames (m).
    measured : int
        Frames measured.
    """
    n = len(keys) - 1
    m = min(frames, n)
    pick = np.unique(((np.arange(m) + 0.5) * n / m).astype(np.int64))
    q, h = positions(pos)
    exact = world_pose(tree, skel, np.asarray(keys, np.float64)[pick])
    encoded = encoded if encoded is not None else encode(tree, skel, keys, pos, joints)
    played = world_pose(tree, skel, decode(*encoded)[pick])
    return displacement(tree, (skel, exact, pos, joints, weights),
                        (skel, played, q[:, :3] * (h / _SHORT), joints, weights))


def report(error) -> str:
    """The command's line on what the compact file costs in motion."""
    rms, worst, measured = error
    return (f"compact: quantised and keys thinned to {TOLERANCE * 1000:g} mm a joint: RMS {rms * 100:.3f} cm, worst "
            f"{worst * 100:.3f} cm of vertex displacement against full precision ({measured} frames measured)")


# ---------------------------------------------------------------------------- leaf cards
def card(lamina: Lamina) -> Lamina:
    """The leaf as a card: the lamina's bounding box in three columns (x at its left edge, its
    middle and its right edge, two rows of vertices), so the cross-curl bends the card as it
    bends the outline at those columns (between them off by at most curl·w²/16, w the box's
    width: 0.7 mm on a 13 cm cherry leaf). The leaf's shape is the alpha of
    :func:`leaf_texture`; the card's triangles wind as the lamina's."""
    (x0, y0), (x1, y1) = lamina.outline.min(axis=0), lamina.outline.max(axis=0)
    outline = np.array([(x, y) for y in (y0, y1) for x in (x0, 0.5 * (x0 + x1), x1)])
    tris = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]])
    (ax, ay), (bx, by), (cx, cy) = lamina.outline[lamina.triangles[0]]
    if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) < 0:  # the lamina's triangles wind clockwise
        tris = tris[:, ::-1]
    return Lamina(lamina.shape, outline, tris, lamina.curl)


def card_mesh(tree) -> TreeMesh:
    """The mesh a glTF file holds: the viewer's (:func:`~treeanim.render.mesh.build_mesh`), each
    leaf's lamina a :func:`card`."""
    return build_mesh(tree, lamina=card(tree.lamina) if tree.lamina is not None else None)


def leaf_uv(uv: np.ndarray, lamina: Lamina) -> np.ndarray:
    """(V, 2) uint16 texture coordinates (normalised) of lamina points ``uv`` (V, 2) in leaf
    units: their place in the lamina's bounding box, the tip at the image's top (glTF's v runs
    down)."""
    lo, hi = lamina.outline.min(axis=0), lamina.outline.max(axis=0)
    st = (np.asarray(uv, np.float64) - lo) / (hi - lo)
    st[:, 1] = 1.0 - st[:, 1]
    return np.round(np.clip(st, 0.0, 1.0) * 65535).astype(np.uint16)


def leaf_texture(lamina: Lamina, size: int = TEXTURE_SIZE) -> bytes:
    """A PNG (size × size): white, its alpha the lamina's shape over its bounding box
    (:func:`leaf_uv`), drawn at 4× and averaged (the edge's coverage, for the client's alpha
    cut and mipmaps)."""
    from PIL import Image, ImageDraw

    big = 4 * size
    lo, hi = lamina.outline.min(axis=0), lamina.outline.max(axis=0)
    px = (lamina.outline - lo) / (hi - lo) * big
    px[:, 1] = big - px[:, 1]
    mask = Image.new("L", (big, big), 0)
    draw = ImageDraw.Draw(mask)
    for tri in lamina.triangles:
        draw.polygon([tuple(p) for p in px[tri]], fill=255)
    image = Image.new("RGBA", (size, size), (255, 255, 255, 0))
    image.putalpha(mask.resize((size, size), Image.Resampling.BOX))
    out = io.BytesIO()
    image.save(out, format="PNG", optimize=True)
    return out.getvalue()
