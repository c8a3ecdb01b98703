"""Joint budgets (export --joints N, --target): the budget is respected, the file validates, the full budget
is today's motion, and the reported error against the full motion falls as the budget grows."""

import re
import subprocess
import sys

import numpy as np
import pytest

import treeanim as ta
from gltf_readback import attribute, clip, joint_world_positions, load
from test_export import export, validate
from treeanim import compact, joints
from treeanim import export as ex
from treeanim.options import joint_budget
from treeanim.render.mesh import build_mesh

ARGS = ("small_cherry", "--seconds", "1", "--fps", "10", "--wind", "8")
REPORT = re.compile(r"joints: ([\d,]+) of ([\d,]+) \(budget ([\d,]+)\); against the full motion: RMS ([\d.]+) cm, "
                    r"worst ([\d.]+) cm")


def test_each_budget_is_respected_validates_and_its_error_falls_as_it_grows(tmp_path):
    errors = {}
    for budget in ("256", "1024", "all"):
        out = tmp_path / f"tree-{budget}.glb"
        res = export(*ARGS, "--joints", budget, "--out", str(out))
        assert res.returncode == 0, res.stderr
        report = validate(out)
        assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]
        doc, blob = load(out)
        count = len(doc.skins[0].joints)
        assert len(doc.animations[0].channels) == count - 1
        used = attribute(doc, blob, "JOINTS_0")
        assert used.max() < count
        if budget == "all":
            assert count == 2522 and "joints: all 2,522 (the full motion)" in res.stdout
            errors[budget] = (0.0, 0.0)
            continue
        assert count <= int(budget)
        m = REPORT.search(res.stdout)
        assert m, res.stdout
        assert int(m[1].replace(",", "")) == count and int(m[2].replace(",", "")) == 2522
        errors[budget] = (float(m[4]), float(m[5]))
        assert 0 < errors[budget][0] <= errors[budget][1] < 20, "centimetres: a leaf's flutter, not a branch's sway"
    rms = [errors[b][0] for b in ("256", "1024", "all")]
    assert rms[0] > rms[1] > rms[2] == 0, errors


def test_full_budget_is_todays_motion(tmp_path):
    """--joints all, and any budget of at least the joint count, write the keys a plain export writes."""
    files = {}
    for name, extra in (("plain", ()), ("all", ("--joints", "all")), ("big", ("--joints", "5000"))):
        files[name] = tmp_path / f"{name}.glb"
        res = export(*ARGS, *extra, "--out", str(files[name]))
        assert res.returncode == 0, res.stderr
    plain = clip(*load(files["plain"]))[1]
    for name in ("all", "big"):
        keys = clip(*load(files[name]))[1]
        assert np.array_equal(keys, plain)


def test_target_chooses_a_budget_and_merged_joints_ride_rigidly(tmp_path):
    out = tmp_path / "unreal.glb"
    res = export(*ARGS, "--target", "unreal", "--precision", "full", "--out", str(out))
    assert res.returncode == 0, res.stderr
    doc, blob = load(out)
    assert len(doc.skins[0].joints) == 256 and "budget 256" in res.stdout
    # Each kept joint of the file sits where the full skeleton, posed by the full motion, carries it
    # rigidly: within the reported worst displacement of the full motion's joint.
    tree = ta.load_preset("small_cherry")
    sim = ta.Simulation(tree, wind=ta.WindField(speed=8.0))
    full = ex.skeleton(tree, sim.present)
    raw = ex.bake(sim, full, 11, 10.0)
    skel, keys, error = joints.fit(tree, full, raw, 10, 256, sim.present, compact.card_mesh(tree))
    assert np.array_equal(clip(doc, blob)[1], keys[:, 1:]), "the command writes what joints.fit returns"
    world, pos = joints.world_pose(tree, full, raw)
    idx = joints.full_index(full, skel)
    baked = joint_world_positions(doc, blob, 10)
    assert np.max(np.linalg.norm(baked - pos[10, idx], axis=1)) <= error[1] + 1e-3


def test_a_budget_with_a_loop_keeps_its_joints_and_closes(tmp_path):
    """--joints 256 --loop: the reduced keys are closed as a full export's are (the last key is
    the first, the seam is reported), and the budget and its error report stand."""
    out = tmp_path / "loop.glb"
    res = export("small_cherry", "--seconds", "2", "--fps", "10", "--wind", "8", "--joints", "256", "--loop", "0.5",
                 "--out", str(out))
    assert res.returncode == 0, res.stderr
    assert REPORT.search(res.stdout)[1] == "256", res.stdout
    m = re.search(r"loop seam: the last key is ([\d.]+)° off the first", res.stdout)
    assert m and float(m[1]) == 0.0, res.stdout
    report = validate(out)
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]
    doc, blob = load(out)
    times, keys = clip(doc, blob)
    assert len(doc.skins[0].joints) == 256 and keys.shape[1] == 255
    assert times[-1] == np.float32(2.0) and np.array_equal(keys[-1], keys[0]), "the key at T repeats the first"


def test_reduce_keeps_any_budget_as_a_hierarchy():
    tree = ta.load_preset("small_cherry")
    sim = ta.Simulation(tree, wind=ta.WindField(speed=8.0))
    full = ex.skeleton(tree)
    raw = ex.bake(sim, full, 9, 10.0)
    world, _ = joints.world_pose(tree, full, raw)
    _, _, pos, joint, _ = ex.skin(tree, build_mesh(tree), full)
    for budget in (2, 3, 50, 256, 1024, 2521):
        skel = joints.reduce(tree, full, world, pos, joint[:, 0], budget)
        assert skel.count == budget
        assert np.all(skel.joint_parent[1:] < np.arange(1, skel.count)) and skel.joint_parent[0] == -1
        used = full.node_joint >= 0
        assert np.all((skel.node_joint[used] >= 0) & (skel.node_joint[used] < skel.count))
        idx = joints.full_index(full, skel)
        assert np.array_equal(full.joint_node[idx], skel.joint_node)
    for bad in ("1", "0", "-3", "x", "2.5"):
        with pytest.raises(ValueError):
            joint_budget(bad)


@pytest.mark.parametrize("args,words", [
    (["--joints", "1"], "at least 2"),
    (["--joints", "many"], "whole number"),
    (["--target", "xbox"], "invalid choice"),
    (["--joints", "256", "--target", "web"], "not allowed with"),
])
def test_bad_budgets_are_refused_in_one_line(tmp_path, args, words):
    res = subprocess.run([sys.executable, "-m", "treeanim", "export", "small_cherry", "--out", "x.glb", *args],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert res.returncode == 2
    assert "Traceback" not in res.stderr and words in res.stderr and len(res.stderr.strip().splitlines()) == 1
    assert not list(tmp_path.iterdir()), "no file is left behind"
