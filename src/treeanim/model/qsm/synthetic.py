"""A synthetic TreeQSM model of known geometry, for the tests, the benchmarks and ``assets/qsm``."""

from __future__ import annotations

import numpy as np


def synthetic_table(height: float = 15.0, dbh: float = 0.4, limbs: int = 10, twigs: int = 4, sub_twigs: int = 0,
                    cylinder_length: float = 0.5, seed: int = 0) -> np.ndarray:
    """A TreeQSM-like table of a known, made-up broadleaf tree (z up, metres).

    A straight vertical stem of ``height`` in cylinders of about ``cylinder_length``, tapering
    linearly so that its diameter at 1.3 m is ``dbh``; ``limbs`` order-1 branches along its upper
    60 %, longest low down, each carrying ``twigs`` order-2 branches along its outer half, each of
    those ``sub_twigs`` order-3 ones. A branch starts at the end of its parent cylinder (so it
    imports with no offset) and its base radius is 0.6 (limbs) or 0.7 of its parent's there.

    Parameters
    ----------
    height, dbh : float
        Stem length (m) and diameter at breast height (m).
    limbs, twigs, sub_twigs : int
        Branches per level.
    cylinder_length : float
        Longest cylinder (m); each branch is cut into equal cylinders no longer than this.
    seed : int
        Seed of the small random turns of azimuth and elevation.

    Returns
    -------
    numpy.ndarray, (N, 14) float
        Columns as :data:`COLUMNS` plus ``added`` (0); parents and branches 1-based.
    """
    rng = np.random.default_rng(seed)
    rows: list[np.ndarray] = []
    taper = 0.9 / height
    r_stem = 0.5 * dbh / (1 - taper * 1.3)  # the stem's radius at its base

    def add(base, direction, length, r0, r1, parent_row, branch_no, order, bend):
        n = max(1, int(np.ceil(length / cylinder_length - 1e-9)))
        t = np.arange(n) / n
        up = np.array([0.0, 0.0, 1.0])
        d = np.asarray(direction, float)
        # Turn the branch upward along its length by ``bend`` radians (in the plane of d and z).
        side = np.cross(d, up)
        side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-9 else np.array([1.0, 0.0, 0.0])
        ang = bend * (t + 0.5 / n)
        dirs = d * np.cos(ang)[:, None] + np.cross(side, d) * np.sin(ang)[:, None]
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        h = length / n
        starts = base + np.concatenate([[np.zeros(3)], np.cumsum(dirs * h, axis=0)[:-1]])
        radii = r0 + (r1 - r0) * (t + 0.5 / n)
        first = len(rows) + 1
        for i in range(n):
            parent = parent_row if i == 0 else first + i - 1
            ext = first + i + 1 if i < n - 1 else 0
            rows.append(np.array([radii[i], h, *starts[i], *dirs[i], parent, ext, branch_no, order, i + 1, 0.0]))
        return first, n, starts, dirs, h, radii

    stem_first, n_stem, s_starts, _, s_h, s_r = add(np.zeros(3), (0, 0, 1), height, r_stem,
                                                    r_stem * (1 - taper * height), 0, 1, 0, 0.0)
    branch_no = 1
    level = [(stem_first, n_stem, s_starts, s_h, s_r, height)]
    counts = (limbs, twigs, sub_twigs)
    ranges = ((0.4, 0.95), (0.45, 0.95), (0.5, 0.95))
    for order, per in enumerate(counts, start=1):
        nxt = []
        for first, n, starts, h, radii, plen in level:
            if per <= 0:
                continue
            lo, hi = ranges[order - 1]
            cyl = np.unique(np.clip(np.round(np.linspace(lo, hi, per) * n - 1).astype(int), 0, n - 1))
            for k, c in enumerate(cyl):
                frac = (c + 1) / n
                az = rng.uniform(0, 2 * np.pi) if order > 1 else k * np.radians(137.5)
                elev = np.radians(rng.uniform(20, 40) if order == 1 else rng.uniform(0, 30))
                parent_dir = np.asarray(rows[first - 1 + c][5:8])
                horiz = np.array([np.cos(az), np.sin(az), 0.0])
                horiz -= parent_dir * (horiz @ parent_dir)
                horiz /= np.linalg.norm(horiz)
                d = horiz * np.cos(elev) + np.array([0.0, 0.0, 1.0]) * np.sin(elev)
                d /= np.linalg.norm(d)
                L = plen * (0.45 * (1.25 - frac) if order == 1 else 0.45 * (1.2 - 0.5 * frac))
                base = starts[c] + h * np.asarray(rows[first - 1 + c][5:8])
                r0 = radii[c] * (0.6 if order == 1 else 0.7)
                branch_no += 1
                got = add(base, d, L, r0, 0.3 * r0, first + c, branch_no, order, np.radians(15.0))
                nxt.append((got[0], got[1], got[2], got[4], got[5], L))
        level = nxt
    return np.array(rows)
