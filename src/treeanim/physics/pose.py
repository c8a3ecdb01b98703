"""What a :class:`~treeanim.physics.paper_sim.PaperSim` shows of its state: the posed nodes
(``positions``, ``rotations``), built lazily once a step, the loads, the pulls and the
objects' tips.

:class:`Pose` is mixed into PaperSim.
"""

from __future__ import annotations

import sys

import numpy as np

from .rotation import qrot


def _unshared_refs() -> int:
    """sys.getrefcount of an array held only by an attribute, seen as in _recycled (measured,
    since the count of a lone object differs between Python versions)."""

    class Holder:
        pass

    h = Holder()
    h.a = np.empty(1)
    old = getattr(h, "a")
    h.a = None
    return sys.getrefcount(old)


_UNSHARED_REFS = _unshared_refs()


class Pose:
    """PaperSim's pose and loads, read-only views of its state."""

    @property
    def rest_positions(self) -> np.ndarray:
        """(N, 3) rest node positions (the tree's)."""
        return self._tree.rest_positions

    def _node_frames(self) -> np.ndarray:
        if self._fn is None:
            self._fn = self._cplan.node_frames(self._frame)
        return self._fn

    def _recycled(self, attr: str, shape: tuple[int, ...]) -> np.ndarray:
        """The array in ``attr`` if nobody outside holds it any more (so overwriting it is
        invisible), else a new one: outputs stay fresh arrays for whoever keeps them, without a
        new allocation (and its page faults) every frame for whoever does not."""
        old = getattr(self, attr)
        setattr(self, attr, None)
        if old is not None and old.shape == shape and sys.getrefcount(old) <= _UNSHARED_REFS:
            old.setflags(write=True)
            return old
        return np.empty(shape)

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) deformed world node positions (read-only; built on first access after a step).

        An array you keep is never changed by later steps.
        """
        if self._pos_out is None:
            buf = self._recycled("_pos_buf", (self._N, 3))
            pos = self._cplan.positions(self._bplan.o, self._node_frames(), self._base, out=buf)
            pos.setflags(write=False)
            self._pos_out = self._pos_buf = pos
        return self._pos_out

    @property
    def rotations(self) -> np.ndarray:
        """(N, 3, 3) world rotations relative to rest of the segment leaving each node.

        See the class notes for the convention. Read-only; built on first access after a step.
        An array you keep is never changed by later steps.
        """
        if self._rot_out is None:
            buf = self._recycled("_rot_buf", (self._N, 3, 3))
            rot = self._cplan.rotations(self._bplan.q, self._node_frames(), out=buf)
            rot.setflags(write=False)
            self._rot_out = self._rot_buf = rot
        return self._rot_out

    @property
    def loads(self) -> np.ndarray:
        """(M, 3) the local loads L = (L_u, L_v, L_w) of the last step (N), a copy."""
        return self._L.T.copy()

    @property
    def modal_loads(self) -> np.ndarray:
        """(M, 3) the oscillator outputs L′ = (L′_u, L′_v, L′_w) (N; N·m for v), a copy."""
        return self._p.T.copy()

    @property
    def pulls(self) -> dict[int, np.ndarray]:
        """Held objects and their world forces (a copy)."""
        return {i: f.copy() for i, f in self._pulls.items()}

    def tip_position(self, i: int) -> np.ndarray:
        """Deformed world position of object ``i``'s tip node.

        Parameters
        ----------
        i : int
            Object index.

        Returns
        -------
        numpy.ndarray, (3,) float

        Raises
        ------
        ValueError
            Unknown object index.
        """
        i = self._check_object(i)
        return self._tip_positions(np.array([i]))[0]

    def _tip_positions(self, objs: np.ndarray) -> np.ndarray:
        """(K, 3) deformed tip positions of objects ``objs`` (no validation)."""
        o = self._bplan.o[:, self._bplan.ofs_of_node[self._tip_node[objs]]]
        return (self._base[:, objs] + qrot(self._frame[:, objs], o)).T
