"""Bake a simulation into a glTF 2.0 file (.glb or .gltf + .bin) for Blender, three.js, engines.

The skeleton has one joint per segment: a joint sits on every node that starts a segment
(an object's tip node moves rigidly with its last segment, so it shares that joint). A joint's
parent is the previous segment's joint, or for an object's base the joint that carries the
parent's attach node; every object root hangs under one root joint at the origin. Because the
simulation keeps segment lengths exactly and children sit exactly on their parents' nodes,
each joint's translation relative to its parent is constant: the animation holds rotations
only: one float32 quaternion key per joint and frame, sharing one time accessor, or in a
compact file 16-bit keys, each joint's thinned where its motion allows (:mod:`treeanim.compact`).
Objects not present at the season (fallen leaves) have no joints and no triangles.

A clip of n frames holds n + 1 keys, at 0, 1/fps, …, n/fps: it lasts n/fps in a client, which
plays from the first key to the last (a loop's last key repeats its first: :mod:`treeanim.loop`).
"""

from __future__ import annotations

import hashlib
import json
import re
import struct
import urllib.parse
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pygltflib as gl

from . import compact as cp
from .files import remove_stale, write_bytes
from .model.tree import Tree
from .physics.rotation import matrix_to_quat
from .render import palette
from .render.mesh import MATERIAL_BLADE, MATERIAL_LAMINA, MATERIAL_PETIOLE, TreeMesh


@dataclass(frozen=True)
class Skeleton:
    """Joints of a tree: one per segment-starting node, plus a root joint 0 at the origin.

    Attributes
    ----------
    joint_node : (J,) int
        Node of each joint (-1 for the root joint).
    joint_parent : (J,) int
        Parent joint (-1 for the root joint).
    node_joint : (N,) int
        The joint each node moves with (a tip node: its last segment's joint; -1 for the
        nodes of objects left out).
    """

    joint_node: np.ndarray
    joint_parent: np.ndarray
    node_joint: np.ndarray

    @property
    def count(self) -> int:
        """Number of joints, the root included."""
        return len(self.joint_node)


def skeleton(tree: Tree, present: np.ndarray | None = None) -> Skeleton:
    """The joint hierarchy of ``tree`` (see the module docstring).

    Parameters
    ----------
    tree : Tree
    present : (M,) bool, optional
        Objects on the tree (:meth:`Tree.leaves_present`): the others' joints are left out,
        so a winter tree has no joints for its fallen leaves. Default: every object.

    Raises
    ------
    ValueError
        If a present object hangs on one that is not.
    """
    N = tree.n_nodes
    tip = np.zeros(N, bool)
    tip[tree.object_start + tree.object_count - 1] = True
    nodes = np.flatnonzero(~tip)
    if present is not None:
        present = np.asarray(present, bool)
        hung = tree.parent[present]
        if np.any((hung >= 0) & ~present[np.maximum(hung, 0)]):
            raise ValueError("a present object hangs on an object that is not present")
        nodes = nodes[present[tree.node_object[nodes]]]
    node_joint = np.full(N, -1, np.int64)
    node_joint[nodes] = np.arange(1, len(nodes) + 1)
    tips = np.flatnonzero(tip)
    node_joint[tips] = node_joint[tips - 1]
    parent_node = nodes - 1  # the previous node of the same object...
    is_base = tree.node_index[nodes] == 0
    obj = tree.node_object[nodes[is_base]]
    parent_node[is_base] = tree.attach_node[obj]  # ...or the parent's attach node (-1 for roots)
    joint_parent = np.where(parent_node >= 0, node_joint[np.maximum(parent_node, 0)], 0)
    return Skeleton(
        joint_node=np.concatenate([[-1], nodes]),
        joint_parent=np.concatenate([[-1], joint_parent]),
        node_joint=node_joint,
    )


# ---------------------------------------------------------------------------- rotations
def quaternions(R: np.ndarray) -> np.ndarray:
    """Unit quaternions in glTF's order (x, y, z, w), w >= 0, of rotation matrices (..., 3, 3)."""
    R = np.asarray(R, float)
    wxyz = matrix_to_quat(R.reshape(-1, 3, 3))  # the project's convention, scalar first
    return wxyz[[1, 2, 3, 0]].T.reshape(R.shape[:-2] + (4,))


def local_rotations(skel: Skeleton, rotations: np.ndarray) -> np.ndarray:
    """(J, 4) quaternions of each joint's rotation relative to its parent joint.

    ``rotations`` (N, 3, 3) are world rotations relative to rest; at rest every joint's frame
    is axis-aligned, so a joint's local rotation is R_parent^T R_joint.
    """
    world = np.concatenate([np.eye(3)[None], rotations[skel.joint_node[1:]]])
    parent = world[np.maximum(skel.joint_parent, 0)]
    local = np.einsum("jki,jkl->jil", parent, world)
    local[0] = np.eye(3)
    return quaternions(local)


def rest_joints(tree: Tree, skel: Skeleton) -> np.ndarray:
    """(J, 3) each joint's world position at rest (the root joint at the origin)."""
    return np.concatenate([np.zeros((1, 3)), tree.rest_positions[skel.joint_node[1:]]])


def rest_translations(tree: Tree, skel: Skeleton) -> np.ndarray:
    """(J, 3) each joint's translation from its parent joint at rest: its local translation,
    as every joint's frame is axis-aligned at rest."""
    rest = rest_joints(tree, skel)
    return rest - np.where(skel.joint_parent[:, None] >= 0, rest[np.maximum(skel.joint_parent, 0)], 0.0)


# ---------------------------------------------------------------------------- mesh
#: The most bytes of animation keys :func:`bake` allocates (float32 quaternions).
MAX_KEY_BYTES = 8e9
#: The most joints one skin holds: glTF's JOINTS_0 indexes them with 16 bits.
MAX_JOINTS = 65536


def check_joints(skel: "Skeleton") -> None:
    """ValueError (one line) for a skeleton of more than :data:`MAX_JOINTS` joints."""
    if skel.count > MAX_JOINTS:
        raise ValueError(f"{skel.count:,} joints: a glTF skin holds at most {MAX_JOINTS:,} (16-bit joint indices); "
                         "export fewer trees (a scene's trees in smaller scenes) or a winter clip")


def bake(sim, skel: Skeleton, frames: int, fps: float, pulls=(), quiet: bool = True) -> np.ndarray:
    """Run ``sim`` for ``frames`` frames at ``fps`` (the offline clock, with the scheduled
    ``pulls``) and record every joint's local rotation at each frame.

    Returns
    -------
    (frames, joints, 4) float32
        Quaternions (x, y, z, w), as :func:`build_gltf` takes them.

    Raises
    ------
    ValueError
        More than :data:`MAX_KEY_BYTES` of keys, or more than :data:`MAX_JOINTS` joints.
    """
    from tqdm import tqdm

    from . import scripted

    check_joints(skel)
    size = frames * skel.count * 16
    if size > MAX_KEY_BYTES:
        raise ValueError(f"{frames:,} frames of {skel.count:,} joints would need {size / 1e9:.0f} GB of keys; "
                         "export fewer seconds or frames per second")
    keys = np.empty((frames, skel.count, 4), np.float32)
    with tqdm(total=frames, desc=f"baking {sim.tree.name}", unit="frame", disable=quiet, leave=False) as bar:
        for k in scripted.frames(sim, frames, fps, pulls):
            keys[k] = local_rotations(skel, sim.rotations)
            bar.update()
    return keys


def _lin(*rgb) -> np.ndarray:
    return np.power(np.asarray(rgb, float), 2.2)


def _smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def _mix(a, b, t):
    return a + (b - a) * np.asarray(t, float)[..., None]


def vertex_colours(tree: Tree, mesh: TreeMesh, season: float) -> np.ndarray:
    """(V, 4) linear RGBA per vertex: the albedo the viewer's vertex shader gives at ``season``.

    This is ``shaders/tree.vert`` (``leaf_color`` and the material branches of ``main``) in
    numpy, so an exported tree has the viewer's bark, leaf and autumn colours.
    """
    mat = mesh.material
    jitter = mesh.vertices["extra"][:, 1].astype(float)
    key = mesh.vertices["extra"][:, 3].astype(float)
    j2 = np.modf(jitter * 13.37)[0]
    c = {name: _lin(*rgb) for name, rgb in palette.COLOURS.items()}
    summer = _mix(c["LEAF_DARK"], c["LEAF_LIGHT"], jitter)
    summer = _mix(summer, c["LEAF_COOL"], 0.35 * j2)
    prog = _smoothstep(0.05 + 0.35 * key, 0.30 + 0.45 * key, season)  # leaves that fall first turn first
    leaf = _mix(summer, c["LEAF_YELLOW"], _smoothstep(0.0, 0.35, prog))
    leaf = _mix(leaf, _mix(c["LEAF_ORANGE"], c["LEAF_RED"], j2), _smoothstep(0.3, 0.7, prog) * (0.55 + 0.45 * jitter))
    leaf = _mix(leaf, c["LEAF_BROWN"], 0.75 * _smoothstep(0.8, 1.0, prog))
    leaf = _mix(leaf, c["LEAF_DRY"] * (0.85 + 0.3 * j2)[:, None], _smoothstep(0.75, 1.0, season))  # winter's withered
    blade = _mix(c["BLADE_BASE"], _mix(c["BLADE_TIP"], c["BLADE_TIP_DRY"], jitter), key)
    blade = _mix(blade, c["BLADE_WINTER"] * (0.6 + 0.4 * key)[:, None], 0.6 * season)
    col = np.select(
        [mat[:, None] == MATERIAL_LAMINA, mat[:, None] == MATERIAL_PETIOLE, mat[:, None] == MATERIAL_BLADE],
        [leaf, _mix(leaf, c["PETIOLE"], 0.4), blade],
        _lin(*tree.bark.color) * (0.92 + 0.16 * jitter)[:, None],  # the species' bark
    )
    return np.column_stack([np.clip(col, 0, 1), np.ones(len(col))])


# ---------------------------------------------------------------------------- container
_WIDTH = {gl.SCALAR: 1, gl.VEC2: 2, gl.VEC3: 3, gl.VEC4: 4, gl.MAT4: 16}


class _Blob:
    """The binary buffer, built as aligned buffer views and accessors."""

    def __init__(self, doc: gl.GLTF2) -> None:
        self.doc, self.parts, self.size = doc, [], 0

    def view(self, data: bytes, target: int | None = None, stride: int | None = None) -> int:
        pad = (-self.size) % 4
        if pad:
            self.parts.append(b"\0" * pad)
            self.size += pad
        self.doc.bufferViews.append(gl.BufferView(buffer=0, byteOffset=self.size, byteLength=len(data), target=target,
                                                  byteStride=stride))
        self.parts.append(data)
        self.size += len(data)
        return len(self.doc.bufferViews) - 1

    def accessor(self, array: np.ndarray, kind: str, component: int, target=None, normalized=None,
                 minmax=False, view=None, offset=0, count=None) -> int:
        """An accessor of ``array``'s rows (in a view of their own unless ``view`` is given); a
        row may be wider than ``kind`` (padding in a strided view): min and max skip the rest."""
        if view is None:
            view = self.view(np.ascontiguousarray(array).tobytes(), target)
        acc = gl.Accessor(bufferView=view, byteOffset=offset or None, componentType=component,
                          count=int(count if count is not None else len(array)), type=kind, normalized=normalized)
        if minmax:
            flat = np.asarray(array).reshape(len(array), -1)[:, :_WIDTH[kind]]
            acc.min = flat.min(axis=0).tolist()
            acc.max = flat.max(axis=0).tolist()
        self.doc.accessors.append(acc)
        return len(self.doc.accessors) - 1

    def bytes(self) -> bytes:
        pad = (-self.size) % 4
        return b"".join(self.parts) + b"\0" * pad


def skin(tree: Tree, mesh: TreeMesh, skel: Skeleton, present: np.ndarray | None = None):
    """The skinned vertices of ``mesh`` on ``skel``: what :func:`build_gltf` writes.

    Linear-blend skinning: a vertex at t along a branch's segment leans from its base frame
    T₀ toward its segment's joint as a cantilever, by t(3 − t)/2 (the renderer's Hermite
    curve, without the tip's overshoot, which blend weights cannot express).

    Returns
    -------
    keep_tris : (T,) bool
        Triangles of present objects.
    used : (V,) bool
        Vertices those triangles use.
    pos : (U, 3) float32
        Their rest positions.
    joints : (U, 4) uint16
        Their joints (a slot with no weight names joint 0).
    weights : (U, 4) uint8
        Their weights, summing to 255.
    """
    keep_tris = np.ones(len(mesh.indices), bool)
    if present is not None:
        tri_obj = np.repeat(np.arange(tree.n_objects), mesh.object_triangles)
        keep_tris = present[tri_obj]
    used = np.zeros(mesh.vertex_count, bool)
    used[mesh.indices[keep_tris].ravel()] = True
    v = mesh.vertices[used]
    ids = v["ids"]
    pos = (tree.rest_positions[ids[:, 0]] + v["offset"]).astype(np.float32)
    t = v["curve"][:, 0].astype(np.float64)
    w2 = v["extra"][:, 0].astype(np.float64) * (1.0 - 0.5 * t * (3.0 - t))
    j1 = skel.node_joint[ids[:, 0]]
    j2 = np.where(ids[:, 1] >= 0, skel.node_joint[np.maximum(ids[:, 1], 0)], 0)  # -1: the ground
    single = (w2 <= 0) | (j1 == j2)
    joints = np.zeros((len(v), 4), np.uint16)
    weights = np.zeros((len(v), 4), np.uint8)  # normalised: each vertex's weights sum to 255
    joints[:, 0] = j1
    joints[:, 1] = np.where(single, 0, j2)
    weights[:, 1] = np.where(single, 0, np.round(w2 * 255)).astype(np.uint8)
    weights[:, 0] = 255 - weights[:, 1]
    joints[weights == 0] = 0  # a joint listed with no weight is noise to clients (and the validator)
    return keep_tris, used, pos, joints, weights


def surface(tree: Tree, mesh: TreeMesh, used: np.ndarray, season: float) -> tuple[np.ndarray, np.ndarray]:
    """The ``used`` vertices' unit normals (V, 3) float32 and colours at ``season`` (V, 4) uint8."""
    nrm = mesh.vertices["normal"][used].astype(np.float64)
    nrm = (nrm / np.linalg.norm(nrm, axis=1, keepdims=True)).astype(np.float32)
    return nrm, np.round(vertex_colours(tree, mesh, season)[used] * 255).astype(np.uint8)


def material() -> gl.Material:
    """The material of an exported tree: its colours are the vertices', both sides drawn."""
    return gl.Material(name="tree", doubleSided=True, pbrMetallicRoughness=gl.PbrMetallicRoughness(
        baseColorFactor=[1, 1, 1, 1], metallicFactor=0.0, roughnessFactor=0.8))


def leaf_material(doc: gl.GLTF2, blob: "_Blob", lamina) -> int:
    """Add the laminas' material to ``doc``: the tree's, cut to the leaf's shape by the alpha of
    :func:`treeanim.compact.leaf_texture` (a PNG in the buffer; alpha mode MASK). Its index."""
    doc.images.append(gl.Image(bufferView=blob.view(cp.leaf_texture(lamina)), mimeType="image/png"))
    doc.samplers.append(gl.Sampler(magFilter=gl.LINEAR, minFilter=gl.LINEAR_MIPMAP_LINEAR, wrapS=gl.CLAMP_TO_EDGE,
                                   wrapT=gl.CLAMP_TO_EDGE))
    doc.textures.append(gl.Texture(sampler=len(doc.samplers) - 1, source=len(doc.images) - 1))
    leaf = material()
    leaf.name, leaf.alphaMode, leaf.alphaCutoff = "leaf", gl.MASK, 0.5
    leaf.pbrMetallicRoughness.baseColorTexture = gl.TextureInfo(index=len(doc.textures) - 1)
    doc.materials.append(leaf)
    return len(doc.materials) - 1


def primitives(doc: gl.GLTF2, blob: "_Blob", tree: Tree, mesh: TreeMesh, used: np.ndarray, index: np.ndarray,
               columns: dict, short: bool) -> list[gl.Primitive]:
    """The mesh's primitives: ``columns`` (name: (array, type, component, normalised), the
    ``used`` vertices' attributes, each in a view of its own) and the triangles ``index`` (T, 3),
    in runs of consecutive vertices of one material each (:func:`treeanim.compact.runs`), each
    of at most 65,535 vertices where ``short`` (16-bit indices): the tree's material, or the
    leaves' (:func:`leaf_material`), whose runs add ``TEXCOORD_0`` (the laminas' vertices are
    consecutive: :func:`~treeanim.render.mesh.build_mesh` adds them together)."""
    leaf = mesh.material[used] == MATERIAL_LAMINA
    doc.materials.append(material())
    kinds = [len(doc.materials) - 1] * 2  # the material of a run without and with laminas
    views = {name: blob.view(a.tobytes(), gl.ARRAY_BUFFER, a.strides[0]) for name, (a, *_) in columns.items()}
    if leaf.any():
        kinds[1] = leaf_material(doc, blob, tree.lamina)
        first = int(np.argmax(leaf))
        uv = cp.leaf_uv(mesh.vertices["uv"][used][leaf], tree.lamina)
        views["TEXCOORD_0"] = blob.view(uv.tobytes(), gl.ARRAY_BUFFER, uv.strides[0])
    order, runs = cp.runs(index, 65535 if short else None, np.flatnonzero(np.diff(leaf)) + 1)
    index = index[order]
    out = []
    for t0, t1, v0, v1 in runs:
        attrs = {name: blob.accessor(a[v0:v1], kind, component, view=views[name], offset=v0 * a.strides[0],
                                     normalized=norm, minmax=name == "POSITION")
                 for name, (a, kind, component, norm) in columns.items()}
        if leaf[v0]:
            attrs["TEXCOORD_0"] = blob.accessor(uv[v0 - first:v1 - first], gl.VEC2, gl.UNSIGNED_SHORT,
                                                view=views["TEXCOORD_0"], offset=(v0 - first) * uv.strides[0],
                                                normalized=True)
        local = (index[t0:t1] - v0).ravel().astype(np.uint16 if short else np.uint32)
        indices = blob.accessor(local, gl.SCALAR, gl.UNSIGNED_SHORT if short else gl.UNSIGNED_INT,
                                gl.ELEMENT_ARRAY_BUFFER, minmax=True)
        out.append(gl.Primitive(attributes=gl.Attributes(**attrs), indices=indices, material=kinds[int(leaf[v0])]))
    return out


def build_gltf(tree: Tree, keys: np.ndarray, fps: float, season: float = 0.0, mesh: TreeMesh | None = None,
               present: np.ndarray | None = None, skel: Skeleton | None = None,
               precision: str = "full", encoded: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[gl.GLTF2, bytes]:
    """The glTF document and its binary buffer.

    Parameters
    ----------
    tree : Tree
    keys : (F, J, 4) float
        Local joint rotations per frame (from :func:`local_rotations`) of the joints of
        :func:`skeleton` ``(tree, present)``; key k plays at k / ``fps``, so the clip lasts
        (F − 1) / ``fps``.
    fps : float
        Frames per second of ``keys``.
    season : float
        Leaf colour.
    mesh : TreeMesh, optional
        The tree's mesh, its leaves cards (:func:`treeanim.compact.card_mesh`), built if not given.
    present : (M,) bool, optional
        Objects on the tree: the others (fallen leaves) are left out of the mesh and the skin.
    skel : Skeleton, optional
        The joints ``keys`` are for: :func:`skeleton` ``(tree, present)`` by default, or one
        reduced to a joint budget (:func:`treeanim.joints.reduce`).
    precision : {"full", "compact"}
        Float32 attributes and every key, or quantised attributes and keys with each joint's
        keys thinned within :data:`treeanim.compact.TOLERANCE` (:mod:`treeanim.compact`).
    encoded : (keys, stride), optional
        A compact file's keys and strides (:func:`treeanim.compact.encode` of ``keys``), if
        already at hand.

    Raises
    ------
    ValueError
        If ``keys`` are not for the skeleton's joints.
    """
    mesh = mesh if mesh is not None else cp.card_mesh(tree)
    skel = skel if skel is not None else skeleton(tree, present)
    if keys.shape[1] != skel.count:
        raise ValueError(f"keys for {keys.shape[1]} joints, the skeleton has {skel.count}")
    check_joints(skel)
    doc = gl.GLTF2(asset=gl.Asset(version="2.0", generator="treeanim"))
    blob = _Blob(doc)

    # --- mesh: rest positions, normals, colours, joints and weights
    keep_tris, used, pos, joints, weights = skin(tree, mesh, skel, present)
    remap = np.cumsum(used) - 1
    nrm, col = surface(tree, mesh, used, season)
    compact = precision == "compact"
    byte_joints = compact and skel.count <= 256
    index = remap[mesh.indices[keep_tris]]
    if compact:  # KHR_mesh_quantization: positions scaled by 1/scale (undone in the inverse bind matrices)
        qpos, scale = cp.positions(pos)
        columns = {"POSITION": (qpos, gl.VEC3, gl.SHORT, True), "NORMAL": (cp.unit(nrm), gl.VEC3, gl.BYTE, True)}
        doc.extensionsUsed = doc.extensionsRequired = ["KHR_mesh_quantization"]
    else:
        scale = 1.0
        columns = {"POSITION": (pos, gl.VEC3, gl.FLOAT, None), "NORMAL": (nrm, gl.VEC3, gl.FLOAT, None)}
    columns.update(COLOR_0=(col, gl.VEC4, gl.UNSIGNED_BYTE, True),
                   JOINTS_0=(joints.astype(np.uint8), gl.VEC4, gl.UNSIGNED_BYTE, None) if byte_joints else
                   (joints, gl.VEC4, gl.UNSIGNED_SHORT, None),
                   WEIGHTS_0=(weights, gl.VEC4, gl.UNSIGNED_BYTE, True))
    doc.meshes.append(gl.Mesh(name=tree.name, primitives=primitives(doc, blob, tree, mesh, used, index, columns, compact)))

    # --- joints: constant local translations, rotations animated
    J = skel.count
    rest = np.concatenate([np.zeros((1, 3)), tree.rest_positions[skel.joint_node[1:]]])
    local_t = rest - np.where(skel.joint_parent[:, None] >= 0, rest[np.maximum(skel.joint_parent, 0)], 0.0)
    first = len(doc.nodes)
    children: list[list[int]] = [[] for _ in range(J)]
    for j, p in enumerate(skel.joint_parent[1:].tolist(), start=1):
        children[p].append(first + j)
    for j in range(J):
        t = local_t[j].tolist()
        doc.nodes.append(gl.Node(name=f"joint{j}", translation=t if any(t) else None, children=children[j] or None))
    ibm = np.zeros((J, 4, 4), np.float32)
    ibm[:] = np.diag([scale, scale, scale, 1.0]).astype(np.float32)
    ibm[:, 3, :3] = -rest  # column-major: the translation column is stored last
    doc.skins.append(gl.Skin(name="skeleton", joints=list(range(first, first + J)), skeleton=first,
                             inverseBindMatrices=blob.accessor(ibm.reshape(J, 16), gl.MAT4, gl.FLOAT)))
    doc.nodes.append(gl.Node(name=tree.name, mesh=0, skin=0))
    doc.scenes.append(gl.Scene(name=tree.name, nodes=[first, len(doc.nodes) - 1]))
    doc.scene = 0

    # --- animation: a joint's every s-th key (s = 1 at full precision), one time accessor per
    # stride, the rotation accessors in one view
    if compact:
        keys, stride = encoded if encoded is not None else cp.encode(tree, skel, keys, pos, joints)
    else:
        stride = np.ones(J, np.int64)
    times = (np.arange(len(keys)) / fps).astype(np.float32)
    t_acc = {s: blob.accessor(times[::s], gl.SCALAR, gl.FLOAT, minmax=True) for s in np.unique(stride[1:]).tolist()}
    kept = [keys[::stride[j], j] for j in range(1, J)]
    rot = cp.shorts(np.concatenate(kept)) if compact else np.concatenate(kept).astype(np.float32)
    view = blob.view(rot.tobytes())
    start = np.concatenate([[0], np.cumsum([len(k) for k in kept])]) * rot.itemsize * 4
    anim = gl.Animation(name="wind")
    for j in range(1, J):
        out = blob.accessor(kept[j - 1], gl.VEC4, gl.SHORT if compact else gl.FLOAT, view=view,
                            offset=int(start[j - 1]), normalized=compact or None)
        anim.samplers.append(gl.AnimationSampler(input=t_acc[int(stride[j])], output=out, interpolation="LINEAR"))
        anim.channels.append(gl.AnimationChannel(sampler=j - 1, target=gl.AnimationChannelTarget(node=first + j, path="rotation")))
    doc.animations.append(anim)
    data = blob.bytes()
    doc.buffers.append(gl.Buffer(byteLength=len(data)))
    return doc, data


def to_json(doc: gl.GLTF2, allow_nan: bool = True) -> bytes:
    """``doc`` as compact JSON: what pygltflib's ``to_json`` writes (empty and None values left
    out), without its deep copy of every value (11 s for the 17,048 joints' nodes, channels
    and accessors of a large cherry)."""
    return json.dumps(gl.delete_empty_keys(_plain(doc)), cls=gl.JsonEncoder, allow_nan=allow_nan,
                      separators=(",", ":")).encode()


def _plain(obj):
    """Dataclasses, lists and dicts as plain dicts and lists (pygltflib's ``gltf_asdict``)."""
    if obj is None or isinstance(obj, (int, float, str)):
        return obj
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, gl.Attributes):
        return dict(obj.__dict__)
    names = getattr(type(obj), "__dataclass_fields__", None)
    return {name: _plain(getattr(obj, name)) for name in names} if names is not None else obj


def write_gltf(path: str | Path, doc: gl.GLTF2, data: bytes) -> list[Path]:
    """Write ``.glb`` (one file) or ``.gltf`` + ``.bin`` atomically; returns the files written.

    A ``.gltf``'s buffer is named after its content (``tree-1a2b3c4d.bin``), written first, and
    the ``.bin`` the previous ``.gltf`` used is removed only once the new ``.gltf`` is in place:
    a run killed at any moment leaves a matching pair (at worst plus an unused ``.bin``).
    """
    path = Path(path)
    if path.suffix.lower() == ".glb":  # the header, the JSON chunk (space-padded), the buffer's chunk
        doc.buffers[0].uri = None
        text = to_json(doc, allow_nan=False)
        text += b" " * (-len(text) % 4)
        write_bytes(path, b"".join([b"glTF", struct.pack("<III", 2, 28 + len(text) + len(data), len(text)), b"JSON",
                                    text, struct.pack("<I", len(data)), b"BIN\0", data]))
        return [path]
    bin_path = path.with_name(f"{path.stem}-{hashlib.sha1(data).hexdigest()[:8]}.bin")
    doc.buffers[0].uri = urllib.parse.quote(bin_path.name)
    old_bin = _buffer_file(path)
    # A killed export's buffer was named after other content: its stale temporary files too
    remove_stale(path.parent, re.compile(re.escape(path.stem) + r"-[0-9a-f]{8}\.bin"))
    write_bytes(bin_path, data)
    write_bytes(path, to_json(doc))
    if old_bin is not None and old_bin != bin_path:
        old_bin.unlink(missing_ok=True)
    return [path, bin_path]


def _buffer_file(gltf: Path) -> Path | None:
    """The ``.bin`` file beside ``gltf`` that an existing ``.gltf`` there names, if any."""
    try:
        uri = json.loads(gltf.read_text(encoding="utf-8"))["buffers"][0]["uri"]
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return None
    name = urllib.parse.unquote(str(uri))
    if "/" in name or "\\" in name or not name.endswith(".bin"):  # only a plain file beside it
        return None
    return gltf.with_name(name)
