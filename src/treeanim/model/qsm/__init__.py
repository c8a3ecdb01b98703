"""TreeQSM cylinder models: read a scanned tree and build a :class:`Tree` from it.

A quantitative structure model (QSM, Raumonen et al. 2013) describes a tree as cylinders, one
a row: radius, length, start x y z, axis x y z, parent, extension, branch, branch order,
position in branch, added (14 columns; TreeQSM 2.4's text export adds mad and SurfCov before
``added`` and UnmodRadius after it: 16 or 17). Metres, z up; cylinders are numbered from 1 in
file order, ``parent`` 0 marks the stem's first cylinder. The table comes as text (whitespace-
or comma-separated, an optional header line, ``#`` or ``%`` comments) or as a MATLAB ``.mat``
file holding TreeQSM's ``cylinder`` struct (alone or inside a ``QSM`` struct) or a plain
matrix of those columns.

Each chain of cylinders of one branch becomes one curved beam object (docs/design.md §3): its
nodes are the cylinders' start points and the last one's end, its diameters the cylinders'
(averaged where two meet). A branch's base sits on the node of its parent cylinder nearest to
where it starts (its start or its end); the branch is moved by that small offset, with what
grows on it. Coordinates turn from z up to y up, (x, y, z) → (x, z, −y), and the stem's first
cylinder starts at the origin.

Every problem is one :class:`~treeanim.errors.QSMError` line naming the file, the row
and what was wrong.
"""

from .convert import build_tree, load_qsm
from .leaves import LEAF_SPACING, SPECIES, Species, parse_leaves
from .read import QSM_SUFFIXES, read_table, write_table
from .synthetic import synthetic_table

__all__ = ["SPECIES", "Species", "QSM_SUFFIXES", "read_table", "load_qsm", "build_tree", "parse_leaves",
           "synthetic_table", "write_table", "LEAF_SPACING"]
