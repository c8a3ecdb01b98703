"""Record the paper model's poses as the reference of tests/test_paper_sim.py.

Run once, with the release whose behaviour the paper model must keep (commit 4ed910f, before the
load path): ``python tests/data/make_paper_reference.py``. When the presets change (issue #13
reshaped the trees, issue 30 again), record again with 4ed910f's ``physics`` package and today's
presets and model (4ed910f's ``WindField`` takes no ``model``: its field is the paper's; the
scenarios whose presets did not change must come out bit for bit). Each scenario is stepped and every
fifth node's position (and, for the small cherry, rotation) is stored after the last step.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

import treeanim as ta

#: name -> (preset, wind speed, season, integrator, dt, steps, pulls: [(object, force, on, off)])
SCENARIOS = {
    "small_cherry_wind": ("small_cherry", 10.0, 0.3, "exact", 1 / 60, 40, []),
    "small_cherry_pull": ("small_cherry", 0.0, 0.0, "exact", 1 / 60, 40, [(3, (0.0, 0.0, 400.0), 0, 20)]),
    "large_cherry_winter_euler": ("large_cherry", 20.0, 0.8, "euler", 1 / 30, 12, []),
    "tulip_poplar_wind": ("tulip_poplar", 15.0, 0.0, "exact", 1 / 30, 12, []),
    "grassland_wind": ("grassland", 15.0, 0.0, "exact", 1 / 30, 12, []),
    "beam_pull": ("beam", 0.0, 0.0, "exact", 1 / 100, 60, [(0, (0.0, 0.0, 30.0), 0, 30)]),
}


def run(preset, speed, season, integrator, dt, steps, pulls, sim_class=None, **sim_kwargs):
    """The poses of one scenario: (every fifth node's positions, rotations).

    ``sim_class`` (default ``ta.Simulation``, the class at 4ed910f) is the simulation to run.
    """
    tree = ta.load_preset(preset)
    wind = ta.WindField(direction=(1.0, 0.0, 0.3), speed=speed, seed=3, model="paper") if speed else None
    sim_class = ta.Simulation if sim_class is None else sim_class
    sim = sim_class(tree, wind=wind, season=season, seed=1, integrator=integrator, **sim_kwargs)
    for k in range(steps):
        for obj, force, on, off in pulls:
            if k == on:
                sim.pull(obj, force)
            if k == off:
                sim.release(obj)
        sim.step(dt)
    return sim.positions[::5].copy(), sim.rotations[::5].copy()


def main() -> None:
    out = {}
    for name, sc in SCENARIOS.items():
        pos, rot = run(*sc)
        out[f"{name}/positions"] = pos
        if name.startswith("small_cherry"):
            out[f"{name}/rotations"] = rot
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    np.savez_compressed(Path(__file__).with_name("paper_reference.npz"), commit=commit, **out)


if __name__ == "__main__":
    main()
