"""Read a baked glTF back, independently of the exporter: accessors, hierarchy, joint poses."""

import urllib.parse
from pathlib import Path

import numpy as np
import pygltflib as gl

_COMPONENTS = {gl.FLOAT: np.float32, gl.UNSIGNED_SHORT: np.uint16, gl.UNSIGNED_BYTE: np.uint8,
               gl.UNSIGNED_INT: np.uint32, gl.SHORT: np.int16, gl.BYTE: np.int8}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def load(path):
    path = Path(path)
    doc = gl.GLTF2().load(str(path))
    if path.suffix == ".glb":
        blob = doc.binary_blob()
    else:
        blob = (path.parent / urllib.parse.unquote(doc.buffers[0].uri)).read_bytes()
    return doc, blob


def accessor(doc, blob, index):
    acc = doc.accessors[index]
    view = doc.bufferViews[acc.bufferView]
    dtype = np.dtype(_COMPONENTS[acc.componentType])
    width = _WIDTH[acc.type]
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    row = (view.byteStride or dtype.itemsize * width) // dtype.itemsize  # a strided view pads each row
    a = np.frombuffer(blob, dtype, count=(acc.count - 1) * row + width, offset=start)
    a = np.lib.stride_tricks.as_strided(a, (acc.count, width), (row * dtype.itemsize, dtype.itemsize))
    if acc.normalized:
        a = np.maximum(a.astype(np.float64) / np.iinfo(dtype).max, -1.0)
    return a


def attribute(doc, blob, name):
    """A vertex attribute of the mesh, its primitives' in turn (a compact file's primitives hold
    consecutive runs of the vertices)."""
    return np.concatenate([accessor(doc, blob, getattr(p.attributes, name)) for p in doc.meshes[0].primitives])


def triangles(doc):
    """The number of triangles of the mesh, over its primitives."""
    return sum(doc.accessors[p.indices].count for p in doc.meshes[0].primitives) // 3


def clip(doc, blob):
    """The first animation's key times (F,) and rotations (F, C, 4), one per channel, at every
    key time of the clip: a channel with fewer keys (a compact file's) is played at those times."""
    anim = doc.animations[0]
    samplers = [anim.samplers[ch.sampler] for ch in anim.channels]
    inputs = {s.input: accessor(doc, blob, s.input)[:, 0] for s in samplers}
    times = max(inputs.values(), key=len)
    keys = [accessor(doc, blob, s.output) for s in samplers]
    keys = [k if len(k) == len(times) else play(inputs[s.input], k[:, None], times, loop=False)[:, 0]
            for s, k in zip(samplers, keys)]
    return times, np.stack(keys, axis=1)


def play(times, keys, t, loop=True):
    """Rotations (T, C, 4) a client shows at times ``t`` (T,) of a looping clip: the time modulo
    the clip's length (three.js's LoopRepeat; not with ``loop`` False), then a slerp between the
    keys around it."""
    t = np.mod(np.asarray(t, float), float(times[-1])) if loop else np.asarray(t, float)
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    u = np.clip((t - times[i]) / (times[i + 1] - times[i]), 0.0, 1.0)[:, None, None]
    a, b = keys[i].astype(float), keys[i + 1].astype(float)
    d = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(d < 0, -b, b)
    angle = np.arccos(np.clip(np.abs(d), 0.0, 1.0))
    s = np.sin(angle)
    small = s < 1e-6
    wa = np.where(small, 1 - u, np.sin((1 - u) * angle) / np.where(small, 1, s))
    wb = np.where(small, u, np.sin(u * angle) / np.where(small, 1, s))
    q = wa * a + wb * b
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def quat_to_matrix(q):
    x, y, z, w = np.moveaxis(np.asarray(q, float), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def joint_world(doc, blob, frame=None):
    """World rotations (J, 3, 3) and positions (J, 3) of every skin joint at key ``frame`` of the
    clip (:func:`clip`; None: at rest, the nodes' own rotations), composed down the node hierarchy."""
    skin = doc.skins[0]
    anim = doc.animations[0]
    rot = {}
    if frame is not None:
        keys = clip(doc, blob)[1][frame]
        for c, ch in enumerate(anim.channels):
            assert ch.target.path == "rotation"
            rot[ch.target.node] = keys[c]
    parent = {}
    for i, node in enumerate(doc.nodes):
        for c in node.children or []:
            parent[c] = i
    world_R, world_t = {}, {}

    def pose(i):
        if i in world_t:
            return
        t = np.asarray(doc.nodes[i].translation or [0.0, 0.0, 0.0], float)
        q = rot.get(i, doc.nodes[i].rotation or [0.0, 0.0, 0.0, 1.0])
        R = quat_to_matrix(np.asarray(q, float) / np.linalg.norm(q))
        if i in parent:
            pose(parent[i])
            p = parent[i]
            world_t[i] = world_t[p] + world_R[p] @ t
            world_R[i] = world_R[p] @ R
        else:
            world_t[i], world_R[i] = t, R

    import sys

    sys.setrecursionlimit(100000)
    for j in skin.joints:
        pose(j)
    return np.array([world_R[j] for j in skin.joints]), np.array([world_t[j] for j in skin.joints])


def joint_world_positions(doc, blob, frame):
    """World position of every skin joint at key ``frame``."""
    return joint_world(doc, blob, frame)[1]


def skinned_vertices(doc, blob, frame=None):
    """(V, 3) the mesh's vertices at key ``frame`` (None: at rest) as a client skins them:
    Σ w_j M_j IBM_j x, the positions and weights decoded from their accessors (normalised
    integers included), so in metres whatever the file's quantisation."""
    R, t = joint_world(doc, blob, frame)
    M = np.zeros((len(R), 4, 4))
    M[:, :3, :3], M[:, :3, 3], M[:, 3, 3] = R, t, 1.0
    ibm = accessor(doc, blob, doc.skins[0].inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1)  # column-major
    skinning = M @ ibm
    x = attribute(doc, blob, "POSITION")
    x = np.column_stack([x, np.ones(len(x))])
    joints = attribute(doc, blob, "JOINTS_0").astype(np.int64)
    weights = attribute(doc, blob, "WEIGHTS_0")
    out = np.zeros((len(x), 3))
    for slot in range(4):
        out += weights[:, slot, None] * np.einsum("vij,vj->vi", skinning[joints[:, slot]], x)[:, :3]
    return out
