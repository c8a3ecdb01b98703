"""Shader wind for engines: the branches' parameters are the simulation's, the static mesh passes
the glTF validator, and the reference shader sways it in three.js in headless Chromium."""

import shutil
from pathlib import Path

import numpy as np
import pytest

import treeanim as ta
from browser import STILL_MS, changed, frames, serve
from gltf_readback import load
from test_export import NODE_MODULES, export, validate
from treeanim import scripted, shader_wind
from treeanim.offline.trace import zero_crossing_frequency

ROOT = Path(__file__).resolve().parents[1]


def test_branch_frequency_and_damping_are_the_simulations():
    """The beam's table entry agrees with a pull and release of the same simulation (another way
    to measure it): frequency within 5 %, damping within 30 % (the ring-down's two halves against
    the release's whole decay)."""
    tree = ta.load_preset("beam")
    table = shader_wind.branch_table(tree)
    sim = ta.Simulation(tree)
    fps, n = 120.0, 720
    x = []
    for k in scripted.frames(sim, n, fps, [scripted.parse_pull("0:0,0,40@0-1")]):
        x.append(sim.tip_position(0)[2])
    t = np.arange(n) / fps
    after = t >= 1.5
    swing = np.array(x)[after] - np.mean(np.array(x)[-120:])
    f = zero_crossing_frequency(t[after], swing)
    assert table.frequency[0] == pytest.approx(f, rel=0.05)
    peaks = [np.max(np.abs(swing[i:i + int(fps / f)])) for i in (0, len(swing) // 2)]
    zeta = np.log(peaks[0] / peaks[1]) / (2 * np.pi * f * (len(swing) // 2) / fps)
    assert table.damping[0] == pytest.approx(zeta, rel=0.3)
    assert table.compliance[0] > 0
    assert np.allclose(np.linalg.norm(table.axis, axis=1), 1.0)


def test_a_vertex_carries_its_trunk_and_its_three_innermost_branches():
    """... and the branches between them: level 1 swings them with its own as one piece, by
    their bends added up."""
    tree = ta.load_preset("small_cherry")
    levels, pivots = shader_wind.level_chains(tree)
    def chain_of(o):
        chain = [int(o)]
        while tree.parent[chain[-1]] >= 0:
            chain.append(int(tree.parent[chain[-1]]))
        return chain

    leaf, chain = max(((o, chain_of(o)) for o in np.flatnonzero(tree.kind == "leaf")), key=lambda c: len(c[1]))
    assert len(chain) > shader_wind.LEVELS
    assert levels[leaf].tolist() == [chain[-1], chain[2], chain[1], chain[0]]
    assert pivots[leaf].tolist() == [chain[-1], chain[-2], chain[1], chain[0]]
    assert levels[0].tolist() == pivots[0].tolist() == [0, -1, -1, -1]
    c = np.arange(1.0, tree.n_objects + 1.0)
    table = shader_wind.BranchTable(*(np.zeros((tree.n_objects, 3)),) * 2, *(np.zeros(tree.n_objects),) * 2, c, 2.0)
    comp = shader_wind.level_compliance(tree, table, levels)
    assert comp[leaf].tolist() == [c[chain[-1]], sum(c[chain[2:-1]]), c[chain[1]], c[chain[0]]]
    assert comp[0].tolist() == [c[0], 0, 0, 0]


def _rotate(p, c, k, a):
    d = p - c
    s, co = np.sin(a)[:, None], np.cos(a)[:, None]
    return c + d * co + np.cross(k, d) * s + k * np.sum(k * d, axis=1)[:, None] * (1.0 - co)


def test_the_mean_lean_it_encodes_is_the_simulations_between_the_calibration_winds():
    """The levels' mean bends (compliance·U^n, applied as the shader applies them, innermost
    first) shift the small cherry's object tips downwind as far as the simulation does at
    10 m/s, a speed it was not measured at (within 20 %; n is Vogel's: 2 + b with b in
    REALISM's −0.3 … −1 for a leafy crown)."""
    tree = ta.load_preset("small_cherry")
    table = shader_wind.branch_table(tree)
    assert 1.0 < table.exponent < 1.7
    U = 10.0
    sim = ta.Simulation(tree, wind=ta.WindField(speed=U))
    tips = tree.object_start + tree.object_count - 1
    shift = [sim.positions[tips, 0] - tree.rest_positions[tips, 0]
             for k in scripted.frames(sim, 600, 60.0, []) if k >= 240]
    levels, pivots = shader_wind.level_chains(tree)
    comp = shader_wind.level_compliance(tree, table, levels)
    p = tree.rest_positions[tips].copy()
    for level in reversed(range(shader_wind.LEVELS)):
        o, pv = np.maximum(levels[:, level], 0), np.maximum(pivots[:, level], 0)
        k = np.cross(table.axis[o], [1.0, 0.0, 0.0])
        k /= np.linalg.norm(k, axis=1, keepdims=True)
        p = np.where((levels[:, level] >= 0)[:, None], _rotate(p, table.pivot[pv], k, comp[:, level] * U**table.exponent), p)
    assert np.mean(p[:, 0] - tree.rest_positions[tips, 0]) == pytest.approx(np.mean(shift), rel=0.2)


def test_the_reference_shader_sways_the_mesh_in_three_js(tmp_path):
    web = tmp_path / "web"
    web.mkdir()
    res = export("small_cherry", "--motion", "shader", "--out", str(web / "tree.glb"))
    assert res.returncode == 0, res.stderr
    assert "shader wind" in res.stdout
    report = validate(web / "tree.glb")
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]
    doc, _ = load(web / "tree.glb")
    attributes = vars(doc.meshes[0].primitives[0].attributes)
    assert {k for k, v in attributes.items() if v is not None} == {"POSITION", "NORMAL", "COLOR_0", "_OBJECT"}, \
        "a vertex carries its object's index, not its branches"
    shutil.copy(ROOT / "examples" / "shader_wind" / "index.html", web)
    shutil.copy(ROOT / "shaders" / "engine_wind.glsl", web)
    assert (NODE_MODULES / "three").is_dir(), f"three is not installed in {NODE_MODULES}: run scripts/test"
    (web / "three").symlink_to(NODE_MODULES / "three")
    with serve(web) as port:
        calm0, calm3, gale2, gale3 = (
            frames(f"http://127.0.0.1:{port}/index.html?{q}", tmp_path / f"profile{i}", STILL_MS)[0]
            for i, q in enumerate(["t=0&wind=0", "t=3&wind=0", "t=2&wind=20", "t=2.4&wind=20"]))
    sky = calm0[0, 0]
    tree = np.abs(calm0 - sky).sum(axis=2) > 30
    assert tree.mean() > 0.03, "the tree is drawn"
    assert np.array_equal(calm0, calm3), "no wind, no motion"

    assert changed(calm0, gale2) > 0.01, "the gale bends the tree"
    assert changed(gale2, gale3) > 0.005, "and it sways"
    # it leans downwind (+x): the crown's weight moves right
    x = np.arange(calm0.shape[1])
    centre = [np.sum(x * (np.abs(a - sky).sum(axis=2) > 30)) / np.sum(np.abs(a - sky).sum(axis=2) > 30) for a in (calm0, gale2)]
    assert centre[1] > centre[0]


def test_shader_motion_refuses_keys_options_in_one_line(tmp_path):
    res = export("beam", "--motion", "shader", "--loop", "1", "--out", str(tmp_path / "x.glb"))
    assert res.returncode == 2
    assert res.stderr.strip().count("\n") == 0 and "--motion shader" in res.stderr


def test_the_table_holds_each_objects_entry_once_where_the_shader_reads_it():
    """Object o's row r is the texel (o mod W, 9·⌊o / W⌋ + r) that tree_wind_fetch reads, in
    bands of W objects (here 100, so the small cherry's 876 objects take nine bands)."""
    tree = ta.load_preset("small_cherry")
    c = np.arange(1.0, tree.n_objects + 1.0)
    table = shader_wind.BranchTable(np.arange(3.0 * tree.n_objects).reshape(-1, 3), np.ones((tree.n_objects, 3)), c, c / 7,
                                    c / 3, 1.5)
    rows = shader_wind.object_rows(tree, table)
    tex = shader_wind.texture(rows, width=100)
    assert tex.shape == (9 * shader_wind.ROWS, 100, 4)
    o = np.arange(tree.n_objects)
    for r in range(shader_wind.ROWS):
        assert np.array_equal(tex[shader_wind.ROWS * (o // 100) + r, o % 100], rows[:, r])
    levels, pivots = shader_wind.level_chains(tree)
    leaf = int(np.flatnonzero(tree.kind == "leaf")[-1])
    assert rows[leaf, :4, :3].tolist() == table.pivot[pivots[leaf]].astype(np.float32).tolist()
    assert rows[leaf, :4, 3].tolist() == c[levels[leaf]].astype(np.float32).tolist()  # frequencies
    assert rows[leaf, 8].tolist() == (c[levels[leaf]] / 7).astype(np.float32).tolist()  # damping ratios
    assert np.allclose(rows[leaf, 4:8, 3], shader_wind.level_compliance(tree, table, levels)[leaf])
    assert rows[0, 1:4, 3].tolist() == rows[0, 5:8, 3].tolist() == rows[0, 8, 1:].tolist() == [0.0] * 3, \
        "the trunk has one level: no frequency (the shader skips the level), compliance or damping on the others"
