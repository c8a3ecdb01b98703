"""Write the project's synthetic TreeQSM models (see README.md beside this file).

Run from the repository root: ``python assets/qsm/make_synthetic.py``. Deterministic: the same
files every time.
"""

import io
from pathlib import Path

import numpy as np
from scipy.io import savemat

from treeanim.model.qsm import synthetic_table, write_table

HERE = Path(__file__).resolve().parent


def cylinder_struct(table: np.ndarray) -> dict:
    """TreeQSM's ``cylinder`` struct of a 14-column table (as TreeQSM saves it in a .mat)."""
    return {"radius": table[:, 0:1], "length": table[:, 1:2], "start": table[:, 2:5], "axis": table[:, 5:8],
            "parent": table[:, 8:9], "extension": table[:, 9:10], "branch": table[:, 10:11],
            "BranchOrder": table[:, 11:12], "PositionInBranch": table[:, 12:13], "added": table[:, 13:14]}


#: The .mat file's 116-byte text header. scipy writes "Platform: posix, Created on: <date>"
#: there, so the file changed at every run (and dirtied the checkout): a fixed one instead.
MAT_HEADER = b"MATLAB 5.0 MAT-file, written by treeanim's assets/qsm/make_synthetic.py".ljust(116)


def mat_bytes(variables: dict) -> bytes:
    """``variables`` as a compressed MATLAB 5 file, the same bytes at every run."""
    buf = io.BytesIO()
    savemat(buf, variables, do_compression=True)
    data = buf.getvalue()
    assert data[:19] == b"MATLAB 5.0 MAT-file" and len(MAT_HEADER) == 116
    return MAT_HEADER + data[116:]


def main(folder: Path = HERE) -> None:
    """Write ``synthetic_broadleaf.txt`` and ``.mat`` into ``folder`` (this one by default)."""
    table = synthetic_table(height=15.0, dbh=0.4, limbs=12, twigs=5, sub_twigs=3, seed=0)
    write_table(folder / "synthetic_broadleaf.txt", table)
    (folder / "synthetic_broadleaf.mat").write_bytes(mat_bytes({"QSM": {"cylinder": cylinder_struct(table)}}))
    print(f"wrote {len(table)} cylinders to {folder / 'synthetic_broadleaf.txt'} and .mat")


if __name__ == "__main__":
    main()
