"""Write the project's synthetic TreeQSM models (see README.md beside this file).

Run from the repository root: ``python assets/qsm/make_synthetic.py``. Deterministic: the same
files every time.
"""

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


def main() -> None:
    table = synthetic_table(height=15.0, dbh=0.4, limbs=12, twigs=5, sub_twigs=3, seed=0)
    write_table(HERE / "synthetic_broadleaf.txt", table)
    savemat(HERE / "synthetic_broadleaf.mat", {"QSM": {"cylinder": cylinder_struct(table)}}, do_compression=True)
    print(f"wrote {len(table)} cylinders to {HERE / 'synthetic_broadleaf.txt'} and .mat")


if __name__ == "__main__":
    main()
