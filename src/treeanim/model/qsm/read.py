"""Reading and writing TreeQSM cylinder tables: text (whitespace or comma separated) and MATLAB .mat files."""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

import numpy as np

from ...errors import QSMError

#: File suffixes read as TreeQSM models.
QSM_SUFFIXES = (".txt", ".csv", ".mat")


#: The columns used, in TreeQSM's order (0-based indices into a row).
COLUMNS = ("radius", "length", "start_x", "start_y", "start_z", "axis_x", "axis_y", "axis_z", "parent",
           "extension", "branch", "branch_order", "position_in_branch")


#: Accepted widths of a row and what follows the 13 columns above.
WIDTHS = {14: "added", 16: "mad, SurfCov, added", 17: "mad, SurfCov, added, UnmodRadius"}


#: A model file larger than this is refused unread (a 100,000-cylinder text table is ~15 MB).
MAX_QSM_BYTES = 64 << 20


#: Most cylinders a model may have (the preset size budget's 200,000 objects, in cylinders).
MAX_CYLINDERS = 200_000

# ---------------------------------------------------------------------------- reading
def _problem(path, row: int | None, what: str, lines: np.ndarray | None = None) -> QSMError:
    where = ""
    if row is not None:
        where = f" row {row + 1}" + (f" (line {int(lines[row])})" if lines is not None else "") + ":"
    return QSMError(f"{path}:{where} {what}")


def _read_bytes(path: Path) -> bytes:
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise QSMError(f"{path}: not a regular file (a QSM must be a .txt, .csv or .mat file)")
        if info.st_size > MAX_QSM_BYTES:
            raise QSMError(f"{path}: {info.st_size:,} bytes; a QSM file may have at most {MAX_QSM_BYTES:,}")
        with open(path, "rb") as f:
            return f.read(MAX_QSM_BYTES + 1)
    except OSError as e:
        raise QSMError(f"{path}: cannot read QSM file ({e.strerror or e})") from None


_SPLIT = re.compile(r"[\s,;]+")


def _read_text(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(N, width) float table and each row's line number."""
    try:
        text = _read_bytes(path).decode("utf-8-sig")
    except UnicodeDecodeError:
        raise QSMError(f"{path}: not a UTF-8 text file") from None
    n_lines = text.count("\n")
    if n_lines > 2 * MAX_CYLINDERS:  # refused unparsed (a row a line; room for comments)
        raise QSMError(f"{path}: {n_lines:,} lines; a model may have at most {MAX_CYLINDERS:,} cylinders")
    rows, numbers, header = [], [], True
    for n, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line or line[0] in "#%":
            continue
        fields = _SPLIT.split(line.strip(" ,;"))
        if header and not _numeric(fields[0]):  # the first line of words: a header, skipped
            header = False
            continue
        header = False
        rows.append(fields)
        numbers.append(n)
    lines = np.array(numbers, np.int64)
    if not rows:
        raise QSMError(f"{path}: empty table: no cylinder rows")
    widths = np.array([len(r) for r in rows])
    width = int(widths[0])
    bad = np.flatnonzero((widths != width) | ~np.isin(widths, list(WIDTHS)))
    if len(bad):
        k = int(bad[0])
        raise _problem(path, k, f"{widths[k]} columns; expected {_widths_text()}", lines)
    try:
        table = np.array(rows, dtype=float)
    except ValueError:
        for k, r in enumerate(rows):
            for c, x in enumerate(r):
                if not _numeric(x):
                    raise _problem(path, k, f"column {c + 1} ({_column_name(c)}) is {x[:20]!r}, not a number",
                                   lines) from None
        raise  # pragma: no cover - np.array failed on numbers float() accepts
    return table, lines


def _numeric(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _column_name(c: int) -> str:
    return COLUMNS[c] if c < len(COLUMNS) else "a trailing column"


def _widths_text() -> str:
    return "14 (radius, length, start x y z, axis x y z, parent, extension, branch, branch order, position in " \
           "branch, added), 16 or 17 (TreeQSM 2.4's text export)"


def _read_mat(path: Path) -> np.ndarray:
    """The cylinder table of a MATLAB file: a ``cylinder`` struct or an (N, 14/16/17) matrix."""
    from scipy.io import loadmat, matlab

    _read_bytes(path)  # the same checks as text (a regular file, its size)
    try:
        data = loadmat(path, simplify_cells=True)
    except NotImplementedError:
        raise QSMError(f"{path}: a MATLAB v7.3 (HDF5) file; save the QSM with save(..., '-v7')") from None
    except (ValueError, TypeError, OSError, matlab.miobase.MatReadError) as e:
        raise QSMError(f"{path}: not a readable MATLAB .mat file ({' '.join(str(e).split())[:100]})") from None
    values = {k: v for k, v in data.items() if not k.startswith("__")}
    for holder in (values, values.get("QSM"), values.get("qsm")):
        if isinstance(holder, (list, np.ndarray)) and len(holder) and isinstance(holder[0], dict):
            holder = holder[0]  # an array of QSMs: the first
        if isinstance(holder, dict) and isinstance(holder.get("cylinder"), dict):
            return _from_struct(path, holder["cylinder"])
    matrices = [v for v in values.values() if isinstance(v, np.ndarray) and v.ndim == 2
                and v.shape[1] in WIDTHS and np.issubdtype(v.dtype, np.number)]
    if len(matrices) != 1:
        raise QSMError(f"{path}: expected a TreeQSM 'cylinder' struct (alone or in a 'QSM' struct) or one "
                       f"matrix of {_widths_text()} columns; found variables {', '.join(sorted(values)) or 'none'}")
    return np.asarray(matrices[0], float)


def _from_struct(path: Path, cyl: dict) -> np.ndarray:
    need = {"radius": 1, "length": 1, "start": 3, "axis": 3, "parent": 1, "extension": 1, "branch": 1,
            "BranchOrder": 1, "PositionInBranch": 1}
    optional = ("extension", "BranchOrder", "PositionInBranch")  # not used to build the tree
    n = None
    cols = {}
    for name, width in need.items():
        if name not in cyl:
            if name in optional:
                continue
            raise QSMError(f"{path}: the cylinder struct has no field {name!r}; expected {', '.join(need)}")
        try:
            if np.iscomplexobj(cyl[name]):
                raise TypeError
            v = np.asarray(cyl[name], float).reshape(-1, width)
        except (TypeError, ValueError):
            raise QSMError(f"{path}: cylinder field {name!r} is not an array of {width} number(s) a row") from None
        n = len(v) if n is None else n
        if len(v) != n:
            raise QSMError(f"{path}: cylinder field {name!r} has {len(v)} rows; 'radius' has {n}")
        cols[name] = v
    return np.hstack([cols.get(name, np.zeros((n, 1))) for name in need] + [np.zeros((n, 1))])  # + added


def read_table(path: str | Path) -> np.ndarray:
    """Read a TreeQSM cylinder table from a text or MATLAB file.

    Parameters
    ----------
    path : str or Path
        ``.mat`` for MATLAB, anything else is read as text.

    Returns
    -------
    numpy.ndarray, (N, 14, 16 or 17) float
        One cylinder a row, in the file's order and units.

    Raises
    ------
    QSMError
        Unreadable file, an empty table, a wrong column count, a field that is not a number.
    """
    path = Path(path)
    if path.suffix.lower() == ".mat":
        table = _read_mat(path)
    else:
        table = _read_text(path)[0]
    if len(table) == 0:
        raise QSMError(f"{path}: empty table: no cylinder rows")
    return table

# ---------------------------------------------------------------------------- writing, synthetic trees
def write_table(path: str | Path, table: np.ndarray, header: bool = True) -> None:
    """Write a cylinder table as TreeQSM-style text (14 columns, one cylinder a line).

    Parameters
    ----------
    path : str or Path
    table : (N, 14) float
    header : bool
        Write a header line of column names first.
    """
    names = "radius length start_x start_y start_z axis_x axis_y axis_z parent extension branch branch_order " \
            "position_in_branch added"
    fmt = ["%.6f"] * 8 + ["%d"] * 6
    np.savetxt(path, np.asarray(table), fmt=fmt, header=names if header else "", comments="")
