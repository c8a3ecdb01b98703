"""USD export: Pixar's own library (usd-core) opens the files, its compliance checker passes
them, and UsdSkel poses the skeleton where the simulation put it."""

import subprocess
import sys

import numpy as np
from pxr import Usd, UsdGeom, UsdSkel, UsdValidation, Vt  # usd-core: a test dependency

from test_export import export, simulate
from treeanim.export import skeleton


def compliance(path):
    """What USD's validators (usdchecker's, every one registered) find wrong in ``path``."""
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    errors = UsdValidation.ValidationContext(validators).Validate(Usd.Stage.Open(str(path)))
    return [e.GetErrorAsString() for e in errors]


def skel_query(stage):
    cache = UsdSkel.Cache()
    root = UsdSkel.Root(stage.GetDefaultPrim())
    cache.Populate(root, Usd.TraverseInstanceProxies())
    binding = cache.ComputeSkelBindings(root, Usd.TraverseInstanceProxies())[0]
    return cache.GetSkelQuery(binding.GetSkeleton()), binding.GetSkinningTargets()[0]


def test_usd_export_poses_the_joints_where_the_simulation_put_them(tmp_path):
    seconds, fps, wind, pulls = 1.0, 15, 8.0, ["3:0,0,150@0.2-0.8"]
    out = tmp_path / "small.usda"
    res = export("small_cherry", "--seconds", str(seconds), "--fps", str(fps), "--wind", str(wind), "--pull", pulls[0],
                 "--out", str(out))
    assert res.returncode == 0, res.stderr
    assert compliance(out) == []
    broken = tmp_path / "broken.usda"  # the validators are awake: a mesh not bound by the skinning API
    broken.write_text(out.read_text().replace('prepend apiSchemas = ["SkelBindingAPI"]', ""))
    assert any("SkelBindingAPI" in e for e in compliance(broken))

    stage = Usd.Stage.Open(str(out))
    n = int(round(seconds * fps))
    assert (stage.GetTimeCodesPerSecond(), stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (fps, 0, n)
    query, skinning = skel_query(stage)
    tree, frames = simulate("small_cherry", seconds, fps, wind, pulls)
    skel = skeleton(tree)
    assert len(query.GetJointOrder()) == skel.count
    assert len(query.GetAnimQuery().GetJointTransformTimeSamples()) == n + 1
    for k in (0, n // 2, n):
        world = np.array(query.ComputeJointWorldTransforms(UsdGeom.XformCache(Usd.TimeCode(k))))  # row-vector
        assert np.max(np.linalg.norm(world[1:, 3, :3] - frames[k][skel.joint_node[1:]], axis=1)) < 1e-3, k
    # The mesh is bound and moves: UsdSkel skins it, at rest at time 0 and displaced by the pull
    rest = np.array(skinning.GetPrim().GetAttribute("points").Get())
    posed = {}
    for k in (0, n // 2):
        points = Vt.Vec3fArray.FromNumpy(rest.astype(np.float32))
        assert skinning.ComputeSkinnedPoints(query.ComputeSkinningTransforms(Usd.TimeCode(k)), points, Usd.TimeCode(k))
        posed[k] = np.array(points)
    assert np.max(np.abs(posed[0] - rest)) < 1e-3
    # ... and at mid-pull its vertices move about as far as its nodes did (a wrong bind would fling
    # them metres away, a missing binding leave them still)
    moved = np.max(np.linalg.norm(posed[n // 2] - rest, axis=1))
    joints_moved = np.max(np.linalg.norm(frames[n // 2] - tree.rest_positions, axis=1))
    assert joints_moved > 0.01 and 0.7 < moved / joints_moved < 2.0, (moved, joints_moved)  # laminas reach past their node


def test_usd_export_in_a_joint_budget_binary(tmp_path):
    out = tmp_path / "budget.usdc"
    res = export("small_cherry", "--seconds", "0.5", "--fps", "10", "--joints", "64", "--out", str(out))
    assert res.returncode == 0, res.stderr
    assert "64 joints" in res.stdout
    assert compliance(out) == []
    stage = Usd.Stage.Open(str(out))
    query, skinning = skel_query(stage)
    assert len(query.GetJointOrder()) == 64
    indices, weights = (np.array(a.Get()).reshape(-1, 4) for a in (skinning.GetJointIndicesPrimvar(),
                                                                  skinning.GetJointWeightsPrimvar()))
    assert indices.max() < 64 and indices.min() >= 0
    assert np.allclose(weights.sum(axis=1), 1.0, atol=1e-6)


def test_usd_without_usd_core_is_one_line(tmp_path):
    """Where usd-core is missing, asking for .usd says what to install, and writes nothing."""
    out = tmp_path / "tree.usd"
    code = ("import sys; sys.modules['pxr'] = None; from treeanim.cli import main; "
            f"sys.exit(main(['export', 'beam', '--seconds', '0.2', '--out', {str(out)!r}]))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert res.returncode == 2
    assert res.stderr.strip().count("\n") == 0 and "usd-core" in res.stderr, res.stderr
    assert not out.exists()
