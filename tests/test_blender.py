"""The README's Blender recipe, run as written where Blender is installed: the clip plays at its
own rate (frame k shows key k) and the scene's range is the clip's."""

from __future__ import annotations

import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from gltf_readback import joint_world_positions, load, skinned_vertices

ROOT = Path(__file__).resolve().parents[1]
BLENDER = shutil.which("blender")

#: Reads back what the recipe made: the scene's range, the action's, and every bone's head and
#: every vertex of the skinned mesh in world space at the frames asked for (argv after "--").
READBACK = """
import bpy, json, sys
s = bpy.context.scene
arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
tree = next(o for o in bpy.data.objects if o.type == "MESH" and o.find_armature())
out = {"fps": s.render.fps, "range": [s.frame_start, s.frame_end],
       "action": list(arm.animation_data.action.frame_range), "frames": {}, "mesh": {}}
for f in map(int, sys.argv[sys.argv.index("--") + 1:]):
    s.frame_set(f)
    out["frames"][f] = {b.name: list(arm.matrix_world @ b.head) for b in arm.pose.bones}
    mesh = tree.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    out["mesh"][f] = [list(tree.matrix_world @ v.co) for v in mesh.vertices]
print("READBACK" + json.dumps(out))
"""

#: Blender 3.4's importer still says ``np.bool``, which numpy 1.24 removed (Debian 12 ships the
#: two together): restore the alias before the recipe runs. Not part of the recipe.
NUMPY_ALIAS = "import numpy; numpy.bool = getattr(numpy, 'bool', bool)"


def readme_blender_command() -> str:
    """The README's ``blender --python-expr ...`` line."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    (line,) = [ln.strip() for ln in text.splitlines() if ln.strip().startswith("blender --python-expr")]
    return line


def test_the_readme_blender_recipe_plays_the_clip_at_its_rate(tmp_path):
    """The clip plays at its own rate, and Blender skins the compact file (quantised positions and keys, the positions'
    scale in the inverse bind matrices, thinned channels) as the file says: every vertex."""
    assert BLENDER is not None, "Blender is not installed: scripts/test installs it (apt-get install blender)"
    recipe = shlex.split(readme_blender_command())
    expr = recipe[recipe.index("--python-expr") + 1]
    fps = int(re.search(r"render\.fps = (\d+)", expr).group(1))
    end = int(re.search(r"frame_end = 0, (\d+)", expr).group(1))
    seconds = (end + 1) / fps  # the README's clip loops: End is T x fps - 1
    out = tmp_path / "cherry.glb"  # the name the recipe imports
    res = subprocess.run([sys.executable, "-m", "treeanim", "export", "small_cherry", "--seconds", f"{seconds:g}", "--fps",
                          str(fps), "--wind", "0", "--pull", "10:0,-5,2@3-5", "--loop", "2", "--out", str(out), "--quiet"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert res.returncode == 0, res.stderr
    frames = [0, end // 2, end, end + 1]
    res = subprocess.run([BLENDER, "-b", "--factory-startup", "--python-expr", NUMPY_ALIAS, "--python-expr", expr,
                          "--python-expr", READBACK, "--", *map(str, frames)],
                         capture_output=True, text=True, cwd=tmp_path, timeout=600)
    line = [ln for ln in res.stdout.splitlines() if ln.startswith("READBACK")]
    assert line, res.stdout[-3000:] + res.stderr[-3000:]
    got = json.loads(line[0][len("READBACK"):])
    assert got["range"] == [0, end]
    assert got["action"] == [0.0, float(end + 1)], "the keys land on frames 0 .. T x fps"

    doc, blob = load(out)
    assert min(doc.accessors[s.input].count for s in doc.animations[0].samplers) < end + 2, "some channels are thinned"
    names = [doc.nodes[j].name for j in doc.skins[0].joints]
    moved = 0.0
    for f in frames:
        bones = got["frames"][str(f)]
        gltf = joint_world_positions(doc, blob, f)
        idx = [i for i, name in enumerate(names) if name in bones]
        assert len(idx) >= len(names) - 1
        blender = np.array([bones[names[i]] for i in idx])
        expected = gltf[idx][:, [0, 2, 1]] * [1, -1, 1]  # glTF's y up is Blender's z up: (x, -z, y)
        assert np.max(np.abs(blender - expected)) < 1e-4, f"frame {f} is not key {f}"
        moved = max(moved, float(np.max(np.linalg.norm(gltf - joint_world_positions(doc, blob, 0), axis=1))))
        mesh = np.array(got["mesh"][str(f)])
        expected = skinned_vertices(doc, blob, f)[:, [0, 2, 1]] * [1, -1, 1]
        assert mesh.shape == expected.shape and np.max(np.abs(mesh - expected)) < 1e-4, f"frame {f}: the mesh"
    assert moved > 0.01, "the test's clip moves"
