"""Static, skinnable triangle meshes for a tree, built once per tree with numpy.

A tree's mesh never changes while it animates: every vertex stores the node whose transform
it follows and its offset from that node at rest, and the vertex shader (``shaders/skin.glsl``)
places it each frame from the node positions and rotations the simulation produces
(docs/design.md §6, §10). :meth:`TreeMesh.skin` is the same formula on the CPU.

A vertex lies on the segment that leaves its node j, at a fraction t of its length (t = 0 at
the node). Its segment's end frames are T₀ = orthonormalise(mix(R[j], R[prev], weight)) —
``prev`` is the previous node at an inner joint (weight ½), the parent's attach node at a
branch's base (weight 1; ``prev = −1``, the ground, for a root), else ``prev = j`` — and
T₁ = orthonormalise(½(R[j] + R[j+1])) at an inner joint or, where the segment ends at the
object's free tip, orthonormalise(1.5·R[j] − ½·T₀) (a cantilever's tip turns 1.5 times its
chord; ``in_curve.y`` = 1). A tip that carries branches ends in their base frame R[j+1] = R[j]
instead (``in_curve.y`` = 0), so a fork's rims stay on it.

The skinning itself, and :meth:`TreeMesh.skin`, its CPU mirror, are in
:mod:`treeanim.render.skinning`: a vertex with t > 0 (the rings inside a branch's segments,
and its tip) rides the segment's cubic Hermite curve, whose rest tangents at its ends (the
vertex's ``tangent0`` and ``tangent1``, the chord's length along the object's unit tangents at
the nodes: the bisector of the neighbouring chords at an inner node, and at an object's ends
turned from the chord as a circular arc through three nodes would be) make the axis through an
object's nodes one smooth curve at rest and bent. So a one-segment twig pulled by its tip
bends as a rod, t²(3 − t)/2 of its tip deflection at t, welded to its parent's (or the
ground's) direction at its base; and a chain of segments has no corner at its inner nodes.

Geometry per object kind (triangle counts: :func:`drawn_triangles`):

- branch: a ``BRANCH_SIDES`` (16)-sided tapered tube whose segments are split in
  :func:`~treeanim.model.tree.curve_bands` bands each (four along a one-segment twig), a ring
  of 16 vertices at each band's ends, square to the rest curve, closed by a 16-triangle fan
  at each end: the tip fan is a low cone, so tips look rounded (flat where branches sit on
  the tip, under their collars); a root's base fan is a flat disc on the ground.
  A child branch's base is a welded collar (R the parent's radius at the joint, r the
  child's): its base ring is a *rim* on the parent's surface, with the parent's surface
  normals (the shading runs on across the joint), and its base fan a cone from the rim down
  to an *apex* sunk in the parent, out of sight. Along a parent the rim is
  ρ = clip(½(R + r), 1.15 r, 1.5 r) (at most 0.95 R) from the child's axis, each side as far
  out along the child as it meets the parent's tube (radius R about the parent's tangent at
  the joint), and the apex on the parent's axis. At a fork (a child on its
  parent's tip) the rim is the parent's end ring, widened to max(R, 1.15 r) and raised so
  that the cone from the apex, 2 R below the end, passes through the end ring: the parent's
  silhouette runs on into each child's; a child turned more than 70° from the parent tilts its
  rim towards it by the excess (an elbow). The collar is skinned with the child's base frame
  (t = 0, T₀ = R[attach], the parent's frame at the joint), so it moves with the parent.
  Collars add no triangles, and 15 vertices a branch (a base fan's apex, one per side).
- leaf: a ``tree.petiole_sides``-sided petiole tube with a ring at each node (no caps, no
  curve: the lamina is rigid on the petiole's tip node), plus the species' lamina
  triangulation placed on the petiole's tip node: v = direction of the
  petiole's last segment, w = ``tree.rest_w`` orthogonalised against v, u = v × w; a lamina
  point (x, y) sits at ``L·(x·u + y·v + curl·x²·w)`` from the tip, L = ``lamina_length``.
- blade: a strip with 2 vertices per node across the blade's w axis (width =
  ``node_diameter``; the strip's face contains the blade's tangent and faces along the bending
  plane), plus one tip triangle to an apex half a segment beyond the tip: 2·(n−1) + 1, drawn
  :data:`BLADE_CLUMP` times (:func:`drawn_triangles`): the simulated blade and copies around
  its root, shorter and leaning, offset from its nodes (their roots in the ground's frame).

Vertex layout (:data:`VERTEX_DTYPE`, 96 bytes, interleaved, attribute format
:data:`VERTEX_FORMAT`)::

    in_ids    ivec4  (node j, prev, object, material)
    in_offset vec3   rest offset from rest_positions[j], metres
    in_normal vec3   rest normal (unit)
    in_extra  vec4   (weight of prev's rotation in T₀, per-object jitter in [0, 1),
                      ambient occlusion in (0, 1], key)
    in_uv     vec2   surface coordinates: bark and petioles (turn around the tube in [0, 1),
                     metres along the object); laminas (x, y) in leaf units; blades
                     (−1 / +1 across, fraction along)
    in_curve  vec2   (t along the segment, 1 where the segment ends at the object's tip); blades
                     (0, half width): tree.vert finds a clump blade's axis by it
    in_tangent0, in_tangent1 vec3   the segment's rest curve's tangents at its ends, metres
                     (branches; 0 elsewhere)

``key`` depends on the material: for lamina and petiole vertices the leaf's drop order
normalised to [0, 1] (0 falls first, and turns colour first); for blades the fraction along
the blade (0 base, 1 tip); 0 for bark. Materials: :data:`MATERIAL_BARK`,
:data:`MATERIAL_PETIOLE`, :data:`MATERIAL_LAMINA`, :data:`MATERIAL_BLADE`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.geometry import arc_length, lamina_frames
from ..model.geometry import perpendicular as _perpendicular
from ..model.geometry import unit as _unit
from ..model.tree import BRANCH_SIDES, Lamina, Tree, curve_bands
from .collars import collars, leaders, outward
from .occlusion import crown_occlusion
from .skinning import hermite, skin_points

MATERIAL_BARK = 0
MATERIAL_PETIOLE = 1
MATERIAL_LAMINA = 2
MATERIAL_BLADE = 3

#: The mesh's parts, each drawn by its own shader program (``PART`` in ``shaders/tree.*``), and
#: the materials each holds: leaves (petioles and laminas), bark, grass blades.
PARTS = {"LEAVES": (MATERIAL_PETIOLE, MATERIAL_LAMINA), "BARK": (MATERIAL_BARK,), "BLADES": (MATERIAL_BLADE,)}

#: Blades drawn per simulated blade (a clump riding its motion, so the paper's 5,000 read as a
#: meadow; Table 1 counts one; each costs about as much as the simulated one to draw), and a
#: clump's radius over its blade's height.
BLADE_CLUMP, BLADE_SPREAD = 3, 0.5

VERTEX_DTYPE = np.dtype(
    [("ids", "<i4", (4,)), ("offset", "<f4", (3,)), ("normal", "<f4", (3,)), ("extra", "<f4", (4,)),
     ("uv", "<f4", (2,)), ("curve", "<f4", (2,)), ("tangent0", "<f4", (3,)), ("tangent1", "<f4", (3,))]
)
#: moderngl buffer format and attribute names matching :data:`VERTEX_DTYPE`.
VERTEX_FORMAT = "4i 3f 3f 4f 2f 2f 3f 3f"
VERTEX_ATTRIBUTES = ("in_ids", "in_offset", "in_normal", "in_extra", "in_uv", "in_curve", "in_tangent0", "in_tangent1")


@dataclass(eq=False)
class TreeMesh:
    """A tree's static mesh.

    Attributes
    ----------
    vertices : (V,) structured array of :data:`VERTEX_DTYPE`
    indices : (T, 3) uint32
        Triangles, counter-clockwise seen from the side the rest normal points to, grouped by
        object in object order: object i's are rows ``object_triangle_start[i]`` to
        ``object_triangle_start[i] + object_triangles[i]``.
    object_triangles : (M,) int
        Triangles of each object (equals ``tree.triangles_per_object()``).
    """

    vertices: np.ndarray
    indices: np.ndarray
    object_triangles: np.ndarray

    @property
    def triangle_count(self) -> int:
        """Total number of triangles."""
        return len(self.indices)

    @property
    def object_triangle_start(self) -> np.ndarray:
        """(M,) int: first row of each object's triangles in :attr:`indices`."""
        return np.concatenate([[0], np.cumsum(self.object_triangles)[:-1]]).astype(np.int64)

    def part_indices(self, part: str) -> np.ndarray:
        """The triangles of one of the mesh's parts.

        Parameters
        ----------
        part : str
            A key of :data:`PARTS`.

        Returns
        -------
        (T', 3) uint32
            Rows of :attr:`indices` whose material is the part's, in their order there.
        """
        return self.indices[np.isin(self.material[self.indices[:, 0]], PARTS[part])]

    @property
    def vertex_count(self) -> int:
        """Total number of vertices."""
        return len(self.vertices)

    @property
    def node(self) -> np.ndarray:
        """(V,) int: the node each vertex follows."""
        return self.vertices["ids"][:, 0]

    @property
    def object(self) -> np.ndarray:
        """(V,) int: the object each vertex belongs to."""
        return self.vertices["ids"][:, 2]

    @property
    def material(self) -> np.ndarray:
        """(V,) int: each vertex's material."""
        return self.vertices["ids"][:, 3]

    def skin(self, positions: np.ndarray, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Deformed vertex positions and normals on the CPU (the vertex shader's formula).

        For exporters and tests; the renderer does this on the GPU.

        Parameters
        ----------
        positions : (N, 3) float
            Node positions, world.
        rotations : (N, 3, 3) float
            Node rotations relative to rest.

        Returns
        -------
        points, normals : (V, 3) float64
        """
        v = self.vertices
        points, F = skin_points(positions, rotations, v["ids"][:, 0], v["ids"][:, 1], v["extra"][:, 0],
                                v["curve"][:, 0], v["curve"][:, 1] > 0.5, v["offset"], v["tangent0"], v["tangent1"])
        normals = np.einsum("vij,vj->vi", F, v["normal"].astype(float))
        return points, normals


def _object_nodes(tree: Tree, objs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flattened nodes of objects ``objs``: (global node, index within object, object)."""
    counts = tree.object_count[objs]
    total = int(counts.sum())
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    k = np.arange(total) - np.repeat(first, counts)
    return np.repeat(tree.object_start[objs], counts) + k, k, np.repeat(objs, counts)


def _node_tangents(tree: Tree, nodes: np.ndarray, k: np.ndarray, obj: np.ndarray, arc: bool = False):
    """Unit tangents at nodes (bisector at inner joints), plus base/tip masks and neighbours.

    ``arc`` (a branch's rest curve): an object's end turns from its chord as much as the
    curve does at the next node in, the other way (as a circular arc through three nodes), so
    its curvature runs on evenly to its ends; else an end's tangent is its chord.
    """
    P = tree.rest_positions
    N = len(P)
    n = tree.object_count[obj]
    base, tip = k == 0, k == n - 1
    nxt = np.where(tip, nodes, np.minimum(nodes + 1, N - 1))
    prv = np.where(base, nodes, nodes - 1)
    d_next = _unit(P[nxt] - P[nodes])
    d_prev = _unit(P[nodes] - P[prv])
    t = np.where(base[:, None], d_next, np.where(tip[:, None], d_prev, _unit(d_prev + d_next, d_next)))
    if arc:
        for end, chord, step in ((base & (n > 2), d_next, 1), (tip & (n > 2), d_prev, -1)):
            i, c = nodes[end], chord[end]
            inner = _unit(c + _unit(P[i + 2 * step] - P[i + step]) * step, c)  # the next node in's tangent
            t[end] = _unit(2.0 * np.sum(c * inner, axis=1, keepdims=True) * c - inner, c)
    return t, base, tip, nxt, prv


def segment_tangents(tangent: np.ndarray, src: np.ndarray, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rest curve's tangents d₀, d₁ (metres) of the segments leaving rows ``src`` of the
    flattened nodes whose unit ``tangent`` :func:`_node_tangents` gives, ``length`` long."""
    return length[:, None] * tangent[src], length[:, None] * tangent[np.minimum(src + 1, len(tangent) - 1)]


class _Parts:
    """Accumulates vertex and triangle blocks."""

    def __init__(self) -> None:
        self.verts: list[np.ndarray] = []
        self.tris: list[np.ndarray] = []
        self.tri_obj: list[np.ndarray] = []
        self.count = 0

    def add(self, node, prev, obj, material, offset, normal, weight, jitter, key, uv=0.0, curve=0.0,
            tangents=(0.0, 0.0)) -> int:
        v = np.zeros(len(node), VERTEX_DTYPE)
        v["ids"] = np.stack([node, prev, obj, np.broadcast_to(material, node.shape)], axis=1)
        v["offset"] = offset
        v["normal"] = normal
        v["extra"][:, 0] = weight
        v["extra"][:, 1] = jitter
        v["extra"][:, 3] = key
        v["uv"] = uv
        v["curve"] = curve
        v["tangent0"], v["tangent1"] = tangents
        base = self.count
        self.verts.append(v)
        self.count += len(v)
        return base

    def triangles(self, tris: np.ndarray, obj: np.ndarray) -> None:
        self.tris.append(tris.reshape(-1, 3))
        self.tri_obj.append(np.broadcast_to(obj, tris.shape[:-1]).reshape(-1))


def _tubes(parts: _Parts, tree: Tree, objs: np.ndarray, sides: int, curved: bool, material: int,
           jitter: np.ndarray, key: np.ndarray) -> None:
    """Tapered tubes with ``sides`` sides over the segments of objects ``objs``.

    ``curved`` (branches): :func:`curve_bands` bands per segment on the deflection curve, the
    base turning with the parent (the ground for a root), and a fan at each end: a flat disc
    under a root, a low cone at the tip, and a child's collar (module notes). Else (petioles):
    a ring at every node, no fans.
    """
    if len(objs) == 0:
        return
    P = tree.rest_positions
    nodes, k, obj = _object_nodes(tree, objs)
    tangent, base, tip, nxt, prv = _node_tangents(tree, nodes, k, obj, curved)
    # A fork's leader continues its parent's tube: from the parent's end ring (its radius, and
    # the rings square to the same w, and the bark running on), without a collar.
    lead = leaders(tree, nodes, tangent) if curved else np.zeros(tree.n_objects, bool)
    r = 0.5 * tree.node_diameter
    r[tree.object_start[lead]] = r[tree.attach_node[lead]]
    frame, along0, arc = np.arange(tree.n_objects), np.zeros(tree.n_objects), arc_length(tree)
    for c in np.flatnonzero(lead):  # parents come first (objects are sorted by level)
        frame[c], along0[c] = frame[tree.parent[c]], along0[tree.parent[c]] + arc[tree.attach_node[c]]
    inner = ~(base | tip)
    # T₀ of the segment leaving each node (module notes).
    prev = np.where(inner, nodes - 1, nodes)
    weight = np.where(inner, 0.5, 0.0)
    child = curved & base & (tree.parent[obj] >= 0)
    if curved:
        prev = np.where(base, np.where(child, tree.attach_node[obj], -1), prev)
        weight = np.where(base, 1.0, weight)
    # An object with a branch on its tip node ends in that branch's base frame.
    carries = np.zeros(tree.n_objects, bool)
    sub = objs[tree.parent[objs] >= 0] if curved else objs[:0]
    par = tree.parent[sub]
    carries[par[tree.attach_node[sub] == tree.object_start[par] + tree.object_count[par] - 1]] = True

    # Rings: bands per segment from each non-tip node, then the object's end ring (t = 1 on
    # the last segment where curved, else the tip node's own ring).
    bands = curve_bands(tree.object_count[obj], tree.joint_turn()[obj]) if curved else np.ones(len(nodes), np.int64)
    reps = np.where(tip, 1, bands)
    src = np.repeat(np.arange(len(nodes)), reps)
    t = (np.arange(len(src)) - np.repeat(np.cumsum(reps) - reps, reps)) / bands[src]
    last = tip[src]  # each object's end ring
    first = base[src] & (t == 0)
    ic = np.flatnonzero(first & child[src] & ~lead[obj[src]])  # a child's base ring: its collar's rim
    if curved:
        src = np.where(last, src - 1, src)
        t = np.where(last, 1.0, t)
    n0, n1 = nodes[src], nxt[src]
    chord = P[n1] - P[n0]
    seg_len = np.linalg.norm(chord, axis=1)
    seg_slope = (r[n1] - r[n0]) / np.where(seg_len > 1e-12, seg_len, 1.0)
    span = np.linalg.norm(P[nxt] - P[prv], axis=1)[src]
    node_slope = np.where(span > 1e-12, (r[nxt] - r[prv])[src] / np.where(span > 1e-12, span, 1.0), 0.0)
    # The rest axis: each segment's Hermite curve, tangent to the object's node tangents
    # (render/skinning.py); a petiole's rings stand on its nodes.
    d0, d1 = segment_tangents(tangent, src, seg_len if curved else np.zeros(len(src)))
    centre, dq = hermite(t, chord, d0, d1)
    tan = _unit(dq, tangent[src])
    slope = np.where(t == 0, node_slope, seg_slope)
    radius = (1.0 - t) * r[n0] + t * r[n1]
    ring_obj = obj[src]

    # Ring frame: the object's w axis projected off the tangent (continuous along a planar
    # object, no twist); a fixed perpendicular where w runs along the tangent.
    w = tree.rest_w[frame[ring_obj]]
    a = _unit(w - np.sum(w * tan, axis=1, keepdims=True) * tan, _perpendicular(tan))
    b = np.cross(tan, a)
    ang = 2.0 * np.pi * np.arange(sides) / sides
    radial = np.cos(ang)[None, :, None] * a[:, None, :] + np.sin(ang)[None, :, None] * b[:, None, :]
    offset = centre[:, None, :] + radius[:, None, None] * radial
    normal = _unit(radial - slope[:, None, None] * tan[:, None, :])
    along = along0[ring_obj] + arc[n0] + t * seg_len
    # A child's base ring is its collar's rim, on the parent's surface with its normals.
    child = ring_obj[ic]
    att, par = tree.attach_node[child], tree.parent[child]
    drawn = np.zeros_like(P)
    drawn[nodes] = tangent
    offset[ic], normal[ic], axis, apex = collars(tree, child, tan[ic], radial[ic], seg_len[ic] / bands[src[ic]],
                                                 _node_tangents(tree, att, att - tree.object_start[par], par), drawn)
    along[ic] = np.mean(np.sum(offset[ic] * tan[ic, None], axis=2), axis=1)
    ring_prev, ring_weight = prev[src], weight[src]

    ends_at_tip = curved & tip[np.minimum(src + 1, len(nodes) - 1)] & ~carries[ring_obj]
    curve = np.stack([t, ends_at_tip.astype(float)], -1)
    uv = np.stack([np.broadcast_to(np.arange(sides) / sides, (len(src), sides)),
                   np.broadcast_to(along[:, None], (len(src), sides))], -1).reshape(-1, 2)
    rep = lambda x: np.repeat(x, sides, axis=0)  # noqa: E731
    v0 = parts.add(rep(n0), rep(ring_prev), rep(ring_obj), material, offset.reshape(-1, 3),
                   normal.reshape(-1, 3), rep(ring_weight), rep(jitter[ring_obj]), rep(key[ring_obj]),
                   uv, rep(curve), (rep(d0), rep(d1)))

    ring = v0 + sides * np.arange(len(src))  # first vertex of each ring
    s0 = np.arange(sides)
    s1 = (s0 + 1) % sides
    band = np.flatnonzero(~last)  # a band from each ring to the next, within an object
    i0, i1 = ring[band, None], ring[band, None] + sides
    quads = np.stack(
        [np.stack([i0 + s0, i0 + s1, i1 + s1], -1), np.stack([i0 + s0, i1 + s1, i1 + s0], -1)], axis=2
    )  # (bands, sides, 2, 3)
    parts.triangles(quads, ring_obj[band, None, None])

    if curved:
        # Base fans, one apex vertex per side: a flat disc facing the ground under a root; a
        # collar's cone from its sunk apex, with the parent's surface normals; none for a leader.
        ib = np.flatnonzero(first & ~lead[obj[src]])
        kb = np.searchsorted(ib, ic)  # the collars among the base fans
        peak = np.zeros((len(ib), 3))
        peak[kb] = apex
        face = np.repeat(-tan[ib, None], sides, axis=1)
        face[kb] = outward(0.5 * (offset[ic][:, s0] + offset[ic][:, s1]), axis)
        cb = parts.add(rep(n0[ib]), rep(ring_prev[ib]), rep(ring_obj[ib]), material, rep(peak),
                       face.reshape(-1, 3), rep(ring_weight[ib]), rep(jitter[ring_obj[ib]]), rep(key[ring_obj[ib]]),
                       np.stack([np.tile((s0 + 0.5) / sides, len(ib)), rep(along[ib])], -1), rep(curve[ib]),
                       (rep(d0[ib]), rep(d1[ib])))
        parts.triangles(np.stack([cb + sides * np.arange(len(ib))[:, None] + s0, ring[ib, None] + s1,
                                  ring[ib, None] + s0], -1), ring_obj[ib, None])
        # Tip fans: a low cone; flat under the collars of branches on the tip; none where a
        # leader runs on.
        led = np.zeros(tree.n_objects, bool)
        led[tree.parent[lead]] = True
        it = np.flatnonzero(last & ~led[obj[src]])
        rise = np.where(carries[ring_obj[it]], 0.0, 0.5 * radius[it])
        ct = parts.add(n0[it], ring_prev[it], ring_obj[it], material, chord[it] + rise[:, None] * tan[it],
                       tan[it], ring_weight[it], jitter[ring_obj[it]], key[ring_obj[it]],
                       np.stack([np.zeros(len(it)), along[it]], -1), curve[it], (d0[it], d1[it]))
        parts.triangles(np.stack([np.broadcast_to(ct + np.arange(len(it))[:, None], (len(it), sides)),
                                  ring[it, None] + s0, ring[it, None] + s1], -1), ring_obj[it, None])


def _laminas(parts: _Parts, tree: Tree, leaves: np.ndarray, jitter: np.ndarray, key: np.ndarray, lam) -> None:
    if lam is None or len(leaves) == 0 or len(lam.triangles) == 0:
        return
    x, y = lam.outline[:, 0], lam.outline[:, 1]
    K = len(x)
    tipn, u, v, w = lamina_frames(tree, leaves)
    L = tree.lamina_length[leaves][:, None, None]
    local = (x[None, :, None] * u[:, None, :] + y[None, :, None] * v[:, None, :]
             + (lam.curl * x * x)[None, :, None] * w[:, None, :])
    offset = L * local
    normal = _unit(w[:, None, :] - (2.0 * lam.curl * x)[None, :, None] * u[:, None, :])
    rep = lambda a: np.repeat(a, K)  # noqa: E731
    v0 = parts.add(rep(tipn), rep(tipn), rep(leaves), MATERIAL_LAMINA, offset.reshape(-1, 3),
                   normal.reshape(-1, 3), 0.0, rep(jitter[leaves]), rep(key[leaves]),
                   np.tile(lam.outline, (len(leaves), 1)))
    tris = v0 + K * np.arange(len(leaves))[:, None, None] + np.asarray(lam.triangles)[None]
    parts.triangles(tris, leaves[:, None])


def _blades(parts: _Parts, tree: Tree, blades: np.ndarray, jitter: np.ndarray, rng: np.random.Generator) -> None:
    if len(blades) == 0:
        return
    P = tree.rest_positions
    nodes, k, obj = _object_nodes(tree, blades)
    t, base, tip, nxt, prv = _node_tangents(tree, nodes, k, obj)
    w = tree.rest_w[obj]
    across = _unit(w - np.sum(w * t, axis=1, keepdims=True) * t, _perpendicular(t))
    normal = np.cross(across, t)
    half = 0.5 * tree.node_diameter[nodes]
    frac = k / (tree.object_count[obj] - 1)
    inner = ~(base | tip)
    rise = P[nodes] - P[tree.object_start[obj]]  # from the blade's root
    m, slot = len(blades), np.searchsorted(blades, obj)
    height = np.linalg.norm(rise[tip], axis=1)
    it, seg = np.flatnonzero(tip), np.flatnonzero(~tip)
    seg_len = np.linalg.norm(P[nodes[it]] - P[prv[it]], axis=1)
    rep = lambda a: np.repeat(a, 2, axis=0)  # noqa: E731
    uv = np.stack([np.tile([-1.0, 1.0], len(nodes)), rep(frac)], -1)
    curve = np.stack([np.zeros(2 * len(nodes)), rep(half)], -1)  # t = 0; the half width
    quad = 2 * seg[:, None, None] + np.array([[[0, 1, 3], [0, 3, 2]]])
    joint_prev, joint_weight = np.where(inner, nodes - 1, nodes), np.where(inner, 0.5, 0.0)
    for c in range(BLADE_CLUMP):  # the simulated blade, then copies round its root, each its own colour
        axis, scale, own, prev, weight = np.zeros((len(nodes), 3)), np.ones(m), jitter[blades], joint_prev, joint_weight
        if c:
            r, az = BLADE_SPREAD * height * np.sqrt(rng.random(m)), rng.uniform(0, 2 * np.pi, m)
            scale, own = rng.uniform(0.55, 1.0, m), rng.random(m)
            lean = np.insert(rng.normal(0.0, 0.25, (m, 2)), 1, 0.0, axis=1) * height[:, None]
            shift = np.column_stack([r * np.cos(az), np.zeros(m), r * np.sin(az)])
            axis = shift[slot] + (scale[slot, None] - 1) * rise + frac[:, None] * lean[slot]
            prev, weight = np.where(base, -1, prev), np.where(base, 1.0, weight)
        offset = rep(axis) + np.stack([-half, half], axis=1).reshape(-1, 1) * rep(across)
        v0 = parts.add(rep(nodes), rep(prev), rep(obj), MATERIAL_BLADE, offset, rep(normal),
                       rep(weight), rep(own[slot]), rep(frac), uv, curve)
        parts.triangles(v0 + quad, obj[seg, None])
        apex = axis[it] + 0.5 * (seg_len * scale)[:, None] * t[it]
        ap = parts.add(nodes[it], nodes[it], obj[it], MATERIAL_BLADE, apex, normal[it], 0.0, own, 1.0, np.array([0.0, 1.0]))
        parts.triangles(np.stack([v0 + 2 * it, v0 + 2 * it + 1, ap + np.arange(len(it))], -1), obj[it])


def drawn_triangles(tree: Tree) -> np.ndarray:
    """(M,) int: the triangles :func:`build_mesh` draws for each object: the paper's
    (:meth:`Tree.triangles_per_object`), a blade's times :data:`BLADE_CLUMP`."""
    return tree.triangles_per_object() * np.where(tree.kind == "blade", BLADE_CLUMP, 1)


def _ambient_occlusion(tree: Tree, verts: np.ndarray, drawn: int) -> np.ndarray:
    """A static occlusion term (1 = open): the crown's leaves' (:mod:`~.occlusion`, the laminas'
    ``drawn`` vertices each sampling their area) and contact with the ground; a blade darker at
    its base."""
    ids = verts["ids"]
    rest = tree.rest_positions[ids[:, 0]] + verts["offset"]
    mat = ids[:, 3]
    lam = np.flatnonzero(mat == MATERIAL_LAMINA)
    area = tree.lamina.area * tree.lamina_length[ids[lam, 2]] ** 2 / drawn if len(lam) else []
    ao = crown_occlusion(rest, rest[lam], area)
    height = max(float(np.ptp(tree.rest_positions[:, 1])), 1e-6)
    ao *= 0.7 + 0.3 * np.clip(rest[:, 1] / (0.04 * height), 0.0, 1.0)  # contact with the ground
    blade = mat == MATERIAL_BLADE
    ao[blade] = 0.45 + 0.55 * verts["extra"][blade, 3]
    return np.clip(ao, 0.05, 1.0)


def build_mesh(tree: Tree, seed: int | None = None, lamina: Lamina | None = None) -> TreeMesh:
    """Build the static skinnable mesh of ``tree`` (vectorised; no loop over objects).

    Parameters
    ----------
    tree : Tree
    seed : int or None
        Seed of the per-object colour jitter; None uses ``tree.seed``.
    lamina : Lamina, optional
        The leaf blade to draw on each leaf: ``tree.lamina`` by default (a glTF file draws a
        card instead: :func:`treeanim.compact.card`).
    """
    lamina = lamina if lamina is not None else tree.lamina
    M = tree.n_objects
    rng = np.random.default_rng([int(tree.seed if seed is None else seed), 0x7E11])
    jitter = rng.random(M)
    kind = np.asarray(tree.kind)
    leaves = np.flatnonzero(kind == "leaf")
    key = np.zeros(M)
    if len(leaves):
        key[leaves] = np.clip(tree.leaf_drop_rank[leaves], 0, None) / max(len(leaves) - 1, 1)

    parts = _Parts()
    _tubes(parts, tree, np.flatnonzero(kind == "branch"), BRANCH_SIDES, True, MATERIAL_BARK, jitter, key)
    _tubes(parts, tree, leaves, int(tree.petiole_sides), False, MATERIAL_PETIOLE, jitter, key)
    _laminas(parts, tree, leaves, jitter, key, lamina)
    _blades(parts, tree, np.flatnonzero(kind == "blade"), jitter, rng)

    verts = np.concatenate(parts.verts) if parts.verts else np.zeros(0, VERTEX_DTYPE)
    tris = np.concatenate(parts.tris).astype(np.uint32) if parts.tris else np.zeros((0, 3), np.uint32)
    tri_obj = np.concatenate(parts.tri_obj) if parts.tri_obj else np.zeros(0, np.int64)
    verts["extra"][:, 2] = _ambient_occlusion(tree, verts, len(lamina.outline) if lamina is not None else 1)
    order = np.argsort(tri_obj, kind="stable")  # group triangles by object
    return TreeMesh(verts, np.ascontiguousarray(tris[order]), np.bincount(tri_obj, minlength=M))
