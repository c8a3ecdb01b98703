"""Record the paper wind field's samples (Eqs. 13–19) as the reference for model="paper".

Run from the repository root at a commit whose WindField is the paper's (the default before
issue 11, 3e9ef3c) to rewrite ``wind_paper_reference.npz``:

    PYTHONPATH=src python tests/data/make_wind_paper_reference.py

Later commits must reproduce these samples bit for bit with ``WindField(model="paper", ...)``.
"""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np

from treeanim.physics.wind import WindField

#: name -> WindField keyword arguments (model="paper" is added where the field knows it).
CASES = {
    "default": {},
    "oblique": dict(direction=(1.0, 0.0, 0.3), speed=10.0, seed=3),
    "coeffs": dict(direction=(-2.0, 0.5, 1.0), speed=17.0, grid=16, beta_u=1.4, beta_vw=1.1,
                   turbulence=1.9, c3=0.7, c4=0.4, c5=2.5, c6=-0.3, seed=11,
                   bounds=((-3.0, 0.0, -2.0), (4.0, 7.5, 3.0))),
    "profile": dict(direction=(0.0, 0.0, -1.0), speed=6.0, c1=0.35, c2=12.0, seed=5),
}
TIMES = (0.0, 0.37, 12.5, 301.0)


def points() -> np.ndarray:
    rng = np.random.default_rng(2024)
    return rng.uniform((-8.0, -1.0, -8.0), (8.0, 14.0, 8.0), (257, 3))


def record() -> dict[str, np.ndarray]:
    paper = "model" in inspect.signature(WindField).parameters
    p = points()
    out = {"points": p, "times": np.array(TIMES)}
    for name, kw in CASES.items():
        wind = WindField(**(dict(kw, model="paper") if paper else kw))
        out[name] = np.stack([wind.sample(p, t) for t in TIMES])
    return out


if __name__ == "__main__":
    path = Path(__file__).with_name("wind_paper_reference.npz")
    np.savez_compressed(path, **record())
    print(f"wrote {path}")
