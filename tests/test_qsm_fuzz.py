"""TreeQSM tables by hypothesis (issue 31): random cylinder tables — of any size, with NaN, ±inf,
negative, huge and subnormal values, ragged rows, wrong widths, parents that name no row or
lead round a cycle, none at all — fed to the TreeQSM loader as a table, a text file and a .mat
file either build a finite tree or are refused with one ValueError line (the project's
QSMError, naming the file): never another exception, never a NaN in the tree."""

from __future__ import annotations

import math
import warnings

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.io import savemat

import treeanim as ta
from treeanim.model.qsm import build_tree, load_qsm

#: Values a cell may be set to: the edges of what floats and the loader's bounds allow.
SPECIAL = [math.nan, math.inf, -math.inf, 0.0, -0.0, -1.0, 0.5, 1e-4, 1e-5, 5e-324, 1e-310, 2.2e-308, 1e6, 1e7,
           1e15, 2.0 ** 53, 1e300, -1e300, 1.7976931348623157e308]
#: Factors a whole column may be scaled by.
SCALES = [0.0, -1.0, 1e-150, 1e-6, 1e3, 1e150, math.inf, math.nan]
COLUMNS = 14


@st.composite
def plausible(draw) -> list[list[float]]:
    """A table TreeQSM could have written: each cylinder starts at its parent's end, most continue
    their parent's branch, the first is the stem's base (parent 0)."""
    n = draw(st.integers(1, 10))
    rows: list[list[float]] = []
    ends, branches, positions = [], [], []
    next_branch = 1
    for i in range(n):
        parent = -1 if i == 0 else draw(st.integers(0, i - 1))
        if parent >= 0 and draw(st.booleans()):
            branch, position = branches[parent], positions[parent] + 1
        else:
            branch, position, next_branch = next_branch, 1, next_branch + 1
        start = np.zeros(3) if parent < 0 else ends[parent]
        axis = np.array([draw(st.floats(-1, 1)), draw(st.floats(-1, 1)), draw(st.floats(0.2, 1))])
        axis /= np.linalg.norm(axis)
        length = draw(st.floats(0.01, 3.0))
        radius = draw(st.floats(1e-3, 0.4))
        ends.append(start + length * axis)
        branches.append(branch)
        positions.append(position)
        rows.append([radius, length, *start, *axis, parent + 1, 0.0, branch, 0.0, position, 0.0])
    return rows


def _mutate(draw, rows: list[list[float]]) -> list[list[float]]:
    rows = [list(r) for r in rows]
    for _ in range(draw(st.integers(0, 3))):
        how = draw(st.sampled_from(["cell", "cell", "parent", "cycle", "scale", "width", "ragged", "drop", "swap"]))
        if not rows:
            break
        i = draw(st.integers(0, len(rows) - 1))
        if how == "cell":
            c = draw(st.integers(0, len(rows[i]) - 1))
            rows[i][c] = draw(st.sampled_from(SPECIAL) | st.floats(allow_nan=True, allow_infinity=True))
        elif how == "parent":  # a parent that names no row, itself, a later row, or is not an integer
            rows[i][8] = draw(st.sampled_from([-1.0, 0.0, 1.5, float(i + 1), float(len(rows)), float(len(rows) + 1),
                                               1e300, math.nan]) | st.integers(-3, len(rows) + 3).map(float))
        elif how == "cycle":  # the stem's base hangs from a later cylinder: no root, or a loop
            rows[0][8] = float(draw(st.integers(1, len(rows))))
        elif how == "scale":
            c = draw(st.integers(0, COLUMNS - 1))
            factor = draw(st.sampled_from(SCALES))
            with np.errstate(all="ignore"):
                for r in rows:
                    if c < len(r):
                        r[c] = float(np.float64(r[c]) * factor)
        elif how == "width":  # every row one column short or long (13, 15) or TreeQSM 2.4's 16 / 17
            extra = draw(st.sampled_from([-1, 1, 2, 3]))
            rows = [r[:extra] if extra < 0 else r + [0.0] * extra for r in rows]
        elif how == "ragged":
            rows[i] = rows[i][:-1] if draw(st.booleans()) else rows[i] + [1.0]
        elif how == "drop":
            del rows[i]
        else:
            j = draw(st.integers(0, len(rows) - 1))
            rows[i], rows[j] = rows[j], rows[i]
    return rows


@st.composite
def tables(draw) -> list[list[float]]:
    """A plausible table mutated, or one of random numbers throughout, or none at all."""
    kind = draw(st.sampled_from(["mutated", "mutated", "mutated", "random", "empty"]))
    if kind == "empty":
        return []
    if kind == "random":
        n, width = draw(st.integers(1, 6)), draw(st.sampled_from([14, 16, 17, 3]))
        cell = st.sampled_from(SPECIAL) | st.floats(allow_nan=True, allow_infinity=True) | st.integers(-2, 8).map(float)
        return [[draw(cell) for _ in range(width)] for _ in range(n)]
    return _mutate(draw, draw(plausible()))


def _text(rows, sep: str, header: bool) -> str:
    lines = ["radius length start_x start_y start_z axis_x axis_y axis_z parent extension branch order pos added"] \
        if header else []
    return "\n".join(lines + [sep.join(repr(float(x)) for x in r) for r in rows]) + "\n"


def _array(rows) -> np.ndarray:
    return np.array(rows, float) if rows else np.empty((0, COLUMNS))


def _checked(load, where: str | None):
    """Run ``load``: a tree whose arrays are all finite, or one clean line (None then); no
    warning either way (numpy's overflow warnings would be lines of their own on the terminal)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            tree = load()
    except ValueError as e:  # QSMError (an InputError): one line, naming the file
        msg = str(e)
        assert "\n" not in msg and len(msg) < 300 + len(where or ""), msg[:400]
        if where is not None:
            assert msg.startswith(f"{where}: "), msg
        return None
    for name in ("rest_positions", "node_diameter", "rest_w", "lamina_length"):
        assert np.all(np.isfinite(getattr(tree, name))), name
    assert tree.n_objects >= 1 and np.all(tree.node_diameter > 0)
    tree.validate()
    with warnings.catch_warnings():  # what `info` and the commands then do with it: finite too
        warnings.simplefilter("error")
        modes = ta.Simulation(tree, model="paper").modes  # beam theory's modes (a QSM's default)
        assert np.isfinite(modes.f).all() and np.isfinite(modes.zeta).all()
        sim = ta.Simulation(tree, wind=ta.WindField(speed=12.0))
        sim.step(1 / 30)
        assert np.isfinite(sim.positions).all()
    return tree


#: A cylinder standing at the origin, 1 m long along z, its stem's first (the fuzz's examples).
ONE = [0.25, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0]


@settings(max_examples=300)
# Found by this fuzz: an axis of 1e300 overflowed its length (a numpy warning, then no
# direction at all); a branch number of 1e300 is whole but no int64 ("invalid value in cast")
@example(rows=[ONE[:5] + [0.0, 0.0, 1e300] + ONE[8:]], form="array", leaves=False)
@example(rows=[ONE[:5] + [5e-324, 0.0, 0.0] + ONE[8:]], form="txt", leaves=False)
@example(rows=[ONE[:10] + [1e300] + ONE[11:]], form="csv", leaves=False)
@given(rows=tables(), form=st.sampled_from(["array", "txt", "csv", "mat", "struct"]), leaves=st.booleans())
def loads_finite_or_refuses_in_one_line(tmp_path_factory, rows, form, leaves):
    species = "cherry" if leaves else None
    if form == "array":
        if len({len(r) for r in rows}) > 1:
            return  # (ragged rows are a text file's problem)
        table = _array(rows)
        _checked(lambda: build_tree(table, name="fuzz", leaves=species), "fuzz")
        return
    folder = tmp_path_factory.mktemp("qsm")
    path = folder / f"fuzz.{'txt' if form in ('txt', 'csv') else 'mat'}"
    if form in ("txt", "csv"):
        path.write_text(_text(rows, "," if form == "csv" else " ", header=bool(len(rows) % 2)))
    else:
        if len({len(r) for r in rows}) > 1:
            return
        table = _array(rows)
        if form == "mat":
            savemat(path, {"cylinders": table})
        else:
            c = table if table.shape[1] >= 11 else np.zeros((len(table), 14))
            savemat(path, {"QSM": {"cylinder": {"radius": c[:, 0], "length": c[:, 1], "start": c[:, 2:5],
                                                "axis": c[:, 5:8], "parent": c[:, 8], "branch": c[:, 10]}}})
    _checked(lambda: load_qsm(path, leaves=species), str(path))


def test_a_random_treeqsm_table_builds_a_finite_tree_or_is_refused_in_one_line(tmp_path_factory):
    loads_finite_or_refuses_in_one_line(tmp_path_factory)


def test_the_plausible_tables_load():
    """The generator's unmutated tables are trees the loader builds (so the fuzz reaches past
    the checks, into the building)."""
    built = []

    @settings(max_examples=20)
    @given(rows=plausible())
    def every(rows):
        built.append(build_tree(np.array(rows), name="plausible"))

    every()
    assert len(built) == 20 and all(np.isfinite(t.rest_positions).all() for t in built)
