"""The paper's model (Hu, Chiba & He 2012) as its own simulation: it reproduces the recorded
reference poses bit for bit."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from treeanim.physics.paper_sim import PaperSim

DATA = Path(__file__).parent / "data"


def _reference_module():
    spec = importlib.util.spec_from_file_location("make_paper_reference", DATA / "make_paper_reference.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_paper_model_reproduces_its_reference_bit_for_bit():
    """The poses the paper model gave before the load path (recorded at commit 4ed910f by
    tests/data/make_paper_reference.py)."""
    ref = np.load(DATA / "paper_reference.npz")
    mod = _reference_module()
    for name, scenario in mod.SCENARIOS.items():
        pos, rot = mod.run(*scenario, sim_class=PaperSim)
        np.testing.assert_array_equal(pos, ref[f"{name}/positions"], err_msg=name)
        if f"{name}/rotations" in ref:
            np.testing.assert_array_equal(rot, ref[f"{name}/rotations"], err_msg=name)
