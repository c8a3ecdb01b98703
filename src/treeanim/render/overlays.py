"""Overlays drawn over the tree as screen-space lines (``line.vert`` + ``line_geom.glsl``).

Each overlay hands the renderer a :class:`LineSet`: pairs of points (GL_LINES), one colour per
point, and optionally a node per point, in which case the point is an offset carried by that
node and skinned on the GPU like the tree (so a static overlay costs no CPU per frame).

- :class:`PullTrace`: the pulled tip's trace, a polyline from a ring buffer, fading with age.
- :class:`LocalFrames`: each object's local frame at its base (u blue, v green, w red; Fig. 5b),
  i.e. ``rotations[base] @ rest frame``; static, skinned.
- :class:`WindSlices`: wind arrows on a few horizontal planes sampled from ``wind(points)``,
  coloured by speed (Fig. 7b).
- :class:`WindArrow`: the wind vector as a red arrow with small blue squares (Fig. 7).
- :class:`Markers`: crosses at points (the viewer's pins).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..model.tree import Tree
from .mesh import arc_length

LINE_DTYPE = np.dtype([("position", "<f4", (3,)), ("color", "<f4", (4,)), ("node", "<i4")])
LINE_FORMAT = "3f 4f i"
LINE_ATTRIBUTES = ("in_position", "in_color", "in_node")


@dataclass
class LineSet:
    """Line segments: rows 2k and 2k+1 are the ends of segment k.

    Attributes
    ----------
    points : (2S, 3) float
        World points, or offsets from ``nodes`` where ``nodes >= 0``.
    colors : (2S, 4) float
        Linear RGBA in [0, 1] (alpha blends).
    nodes : (2S,) int or None
        Node carrying each point (−1 or None: a world point).
    """

    points: np.ndarray
    colors: np.ndarray
    nodes: np.ndarray | None = None

    def packed(self) -> np.ndarray:
        """The vertices as :data:`LINE_DTYPE`."""
        out = np.zeros(len(self.points), LINE_DTYPE)
        out["position"] = self.points
        out["color"] = self.colors
        out["node"] = -1 if self.nodes is None else self.nodes
        return out


class Overlay:
    """Base class. ``width``: line width in pixels; ``on_top``: drawn without depth test;
    ``static``: :meth:`lines` depends only on the tree, so the renderer uploads it once."""

    width: float = 2.0
    on_top: bool = True
    static: bool = False

    def lines(self, tree: Tree) -> LineSet | None:
        """The lines to draw this frame, or None."""
        raise NotImplementedError


# ---------------------------------------------------------------------------- pull trace
class PullTrace(Overlay):
    """The trace of a point (the pulled tip) over time: a ring buffer drawn as a polyline.

    Parameters
    ----------
    capacity : int
        Points kept (older ones are dropped).
    color : (4,) float
        Colour of the newest point; older points fade to transparent.
    """

    def __init__(self, capacity: int = 2000, color=(1.0, 0.85, 0.15, 1.0), width: float = 2.0,
                 on_top: bool = True) -> None:
        self.capacity = int(capacity)
        self.color = np.asarray(color, float)
        self.width = width
        self.on_top = on_top
        self._buf = np.zeros((self.capacity, 3))
        self._next = 0
        self._size = 0

    def push(self, point) -> None:
        """Append one point (3,)."""
        self.extend(np.reshape(point, (1, 3)))

    def extend(self, points) -> None:
        """Append points (K, 3) in order."""
        pts = np.asarray(points, float).reshape(-1, 3)[-self.capacity:]
        k = len(pts)
        self._buf[(self._next + np.arange(k)) % self.capacity] = pts
        self._next = (self._next + k) % self.capacity
        self._size = min(self._size + k, self.capacity)

    def clear(self) -> None:
        self._next = 0
        self._size = 0

    def __len__(self) -> int:
        return self._size

    @property
    def points(self) -> np.ndarray:
        """(K, 3) the kept points, oldest first."""
        if self._size < self.capacity:
            return self._buf[: self._size].copy()
        return np.roll(self._buf, -self._next, axis=0)

    def lines(self, tree: Tree) -> LineSet | None:
        p = self.points
        if len(p) < 2:
            return None
        age = np.linspace(0.0, 1.0, len(p))  # 0 oldest .. 1 newest
        col = np.tile(self.color, (len(p), 1))
        col[:, 3] *= 0.15 + 0.85 * age
        idx = np.repeat(np.arange(len(p)), 2)[1:-1]
        return LineSet(p[idx], col[idx])


# ---------------------------------------------------------------------------- markers
class Markers(Overlay):
    """A three-armed cross at each of :attr:`points` ((K, 3) world), arms ``size`` m long.

    Parameters
    ----------
    size : float
        Length of each arm (m).
    color : (4,) float
    """

    def __init__(self, size: float = 0.1, color=(0.35, 0.9, 1.0, 1.0), width: float = 3.0) -> None:
        self.size = float(size)
        self.color = np.asarray(color, float)
        self.width = width
        self.points = np.zeros((0, 3))

    def lines(self, tree: Tree) -> LineSet | None:
        p = np.asarray(self.points, float).reshape(-1, 3)
        if not len(p):
            return None
        arms = 0.5 * self.size * np.repeat(np.eye(3), 2, axis=0) * np.tile([[-1.0], [1.0]], (3, 1))  # (6, 3)
        pts = (p[:, None, :] + arms[None]).reshape(-1, 3)
        return LineSet(pts, np.tile(self.color, (len(pts), 1)))


# ---------------------------------------------------------------------------- local frames
class LocalFrames(Overlay):
    """Each object's local frame (u blue, v green, w red) at its base node (Fig. 5b).

    The rest frame is v = first segment's direction, w = ``rest_w`` orthogonalised against v,
    u = v × w; the axes are carried by the base node, so they turn with ``rotations[base]``.

    Parameters
    ----------
    scale : float
        Axis length as a fraction of each object's length.
    kinds : tuple of str
        Object kinds shown.
    """

    static = True

    def __init__(self, scale: float = 0.3, kinds=("branch", "leaf", "blade"), width: float = 1.5,
                 on_top: bool = True) -> None:
        self.scale = float(scale)
        self.kinds = tuple(kinds)
        self.width = width
        self.on_top = on_top

    def lines(self, tree: Tree) -> LineSet | None:
        objs = np.flatnonzero(np.isin(tree.kind, self.kinds))
        if len(objs) == 0:
            return None
        P = tree.rest_positions
        base = tree.object_start[objs]
        last = base + tree.object_count[objs] - 1
        v = P[base + 1] - P[base]
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        w = tree.rest_w[objs] - np.sum(tree.rest_w[objs] * v, axis=1, keepdims=True) * v
        w /= np.maximum(np.linalg.norm(w, axis=1, keepdims=True), 1e-12)
        u = np.cross(v, w)
        length = arc_length(tree)[last]
        leaf = tree.kind[objs] == "leaf"
        length = np.where(leaf, length + tree.lamina_length[objs], length)
        s = (self.scale * length)[:, None]
        K = len(objs)
        pts = np.zeros((K, 3, 2, 3))
        pts[:, 0, 1], pts[:, 1, 1], pts[:, 2, 1] = s * u, s * v, s * w
        col = np.zeros((K, 3, 2, 4))
        col[:, 0] = (0.15, 0.35, 1.0, 1.0)  # u blue
        col[:, 1] = (0.1, 0.9, 0.2, 1.0)    # v green
        col[:, 2] = (1.0, 0.15, 0.1, 1.0)   # w red
        nodes = np.broadcast_to(base[:, None, None], (K, 3, 2))
        return LineSet(pts.reshape(-1, 3), col.reshape(-1, 4), nodes.reshape(-1))


# ---------------------------------------------------------------------------- wind
def _speed_colors(t: np.ndarray) -> np.ndarray:
    """Blue → cyan → yellow → red for t in [0, 1]."""
    stops = np.array([[0.1, 0.3, 1.0], [0.1, 0.9, 1.0], [1.0, 0.9, 0.1], [1.0, 0.15, 0.05]])
    x = np.clip(t, 0.0, 1.0) * (len(stops) - 1)
    i = np.minimum(x.astype(int), len(stops) - 2)
    f = (x - i)[:, None]
    return stops[i] * (1 - f) + stops[i + 1] * f


class WindSlices(Overlay):
    """Wind arrows on horizontal planes through ``bounds``, from ``wind(points) -> (K, 3)``.

    Parameters
    ----------
    wind : callable
        Wind velocity at world points (K, 3) -> (K, 3) m/s (e.g. ``lambda p:
        field.sample(p, sim.time)``).
    bounds : ((x0, y0, z0), (x1, y1, z1))
        Box the planes span.
    heights : sequence of float
        Plane heights as fractions of the box's height.
    resolution : int
        Arrows per side of each plane.
    reference_speed : float or None
        Speed drawn one grid spacing long and coloured red; None uses the largest sampled.
    """

    def __init__(self, wind: Callable[[np.ndarray], np.ndarray], bounds, heights=(0.25, 0.55, 0.85),
                 resolution: int = 10, reference_speed: float | None = None, width: float = 1.5,
                 on_top: bool = False) -> None:
        self.wind = wind
        self.bounds = (np.asarray(bounds[0], float), np.asarray(bounds[1], float))
        self.heights = tuple(heights)
        self.resolution = int(resolution)
        self.reference_speed = reference_speed
        self.width = width
        self.on_top = on_top
        lo, hi = self.bounds
        g = (np.arange(self.resolution) + 0.5) / self.resolution
        gx, gh, gz = np.meshgrid(g, np.asarray(self.heights, float), g, indexing="ij")
        self.sample_points = lo + np.stack([gx, gh, gz], -1).reshape(-1, 3) * (hi - lo)
        self.spacing = float(np.max((hi - lo)[[0, 2]]) / self.resolution)

    def lines(self, tree: Tree) -> LineSet | None:
        p = self.sample_points
        U = np.asarray(self.wind(p), float).reshape(-1, 3)
        speed = np.linalg.norm(U, axis=1)
        ref = self.reference_speed or float(speed.max())
        if ref <= 0:
            return None
        tip = p + U * (0.9 * self.spacing / ref)
        d = U / np.maximum(speed, 1e-12)[:, None]
        side = np.cross(d, [0.0, 1.0, 0.0])
        side /= np.maximum(np.linalg.norm(side, axis=1, keepdims=True), 1e-12)
        head = 0.25 * np.linalg.norm(tip - p, axis=1, keepdims=True)
        h1 = tip - head * d + 0.5 * head * side
        h2 = tip - head * d - 0.5 * head * side
        pts = np.stack([p, tip, tip, h1, tip, h2], axis=1)  # shaft and two barbs
        c = np.concatenate([_speed_colors(speed / ref), np.ones((len(p), 1))], axis=1)
        cols = np.repeat(c[:, None, :], 6, axis=1)
        cols[:, 0, :3] *= 0.35  # dark tail, bright head: the direction reads at a glance
        return LineSet(pts.reshape(-1, 3), cols.reshape(-1, 4))


class WindArrow(Overlay):
    """The wind vector: a red arrow with small blue squares along it (Fig. 7).

    Parameters
    ----------
    direction : (3,) float
        Wind direction (any length).
    speed : float
        m/s; the arrow is ``length`` long at ``reference_speed`` and scales with the speed.
    origin : (3,) float
        Where the arrow starts.
    length : float
        Arrow length in metres at ``reference_speed``.
    """

    def __init__(self, direction=(1.0, 0.0, 0.0), speed: float = 5.0, origin=(0.0, 0.0, 0.0),
                 length: float = 1.0, reference_speed: float = 10.0, width: float = 3.0,
                 on_top: bool = True) -> None:
        self.direction = np.asarray(direction, float)
        self.speed = float(speed)
        self.origin = np.asarray(origin, float)
        self.length = float(length)
        self.reference_speed = float(reference_speed)
        self.width = width
        self.on_top = on_top

    def lines(self, tree: Tree) -> LineSet | None:
        n = np.linalg.norm(self.direction)
        if n == 0 or self.speed <= 0:
            return None
        d = self.direction / n
        L = self.length * max(self.speed / self.reference_speed, 0.1)
        side = np.cross(d, [0.0, 1.0, 0.0])
        side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-9 else np.array([1.0, 0.0, 0.0])
        up = np.cross(side, d)
        o = self.origin
        tip = o + L * d
        hl = 0.18 * self.length
        red = (1.0, 0.1, 0.05, 1.0)
        blue = (0.15, 0.3, 1.0, 1.0)
        pts = [o, tip, tip, tip - hl * d + 0.5 * hl * side, tip, tip - hl * d - 0.5 * hl * side]
        cols = [red] * 6
        q = 0.04 * self.length
        for f in np.linspace(0.0, 1.0, 5)[:-1]:
            c = o + f * (tip - o)
            corners = [c + q * (a * side + b * up) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            for k in range(4):
                pts += [corners[k], corners[(k + 1) % 4]]
                cols += [blue, blue]
        return LineSet(np.array(pts), np.array(cols))
