"""Scenes drawn and exported (issue 28): each shipped scene renders offscreen (EGL) with its trees
spread over the picture, the command line renders and exports a scene file, and the viewer (on a
headless window) opens one. The scene API and files: test_scenes."""

from __future__ import annotations

from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

import treeanim as ta
from app_helpers import DT, H, W
from gltf_readback import joint_world_positions, load
from test_export import validate
from treeanim import cli, scripted
from treeanim.app.headless import HeadlessWindow
from treeanim.app.viewer import Viewer
from treeanim.export import skeleton
from treeanim.render.camera import OrbitCamera

SCENE = '''name = "pair"
type = "scene"
seed = 2
[[trees]]
tree = "beam"
position = [-1.5, 0.0, 0.0]
[[trees]]
tree = "beam"
position = [1.5, 0.0, 0.5]
heading = 90.0
scale = 0.8
[[scatter]]
tree = "{meadow}"
count = 2
area = [4.0, 1.0]
centre = [0.0, 2.0]
spacing = 2.0
'''
MEADOW = Path(__file__).resolve().parents[1] / "assets" / "presets" / "scenes" / "plants" / "meadow.toml"


@pytest.fixture()
def pair(tmp_path) -> Path:
    path = tmp_path / "pair.toml"
    path.write_text(SCENE.format(meadow=MEADOW))
    return path


def changed(a, b, thr=24):
    return np.abs(a.astype(int) - b.astype(int)).max(axis=2) > thr


@pytest.mark.parametrize("name", ["orchard", "woodland"])
def test_each_shipped_scene_renders_its_trees_across_the_picture(offscreen, name):
    scene = ta.load_scene(name)
    sim = ta.Simulation(scene, wind=ta.WindField(speed=20.0))
    for _ in range(3):
        sim.step(1 / 60)
    offscreen.resize(240, 135)
    r = offscreen.load(scene)
    cam = OrbitCamera(azimuth=15.0, elevation=20.0)
    cam.frame(r.bounds(), aspect=240 / 135)
    offscreen.update(scene.rest_positions, np.tile(np.eye(3), (scene.n_nodes, 1, 1)),
                     present=np.zeros(scene.n_objects, bool))
    bare = offscreen.render(cam)
    offscreen.update(sim.positions, sim.rotations, present=sim.shown)
    img = offscreen.render(cam)
    assert np.all(np.isfinite(sim.positions)) and offscreen.ctx.error == "GL_NO_ERROR"
    mask = changed(img, bare)
    # (the woodland's small plants are thin, green over green, at this size: 1.6 % of the pixels)
    assert mask.mean() > (0.04 if name == "orchard" else 0.01), mask.mean()
    cols = np.flatnonzero(mask.sum(axis=0) > 2)
    assert cols.max() - cols.min() > 0.5 * 240  # trees from one side of the picture to the other


def test_the_command_line_renders_a_scene_file_and_refuses_the_papers_model(tmp_path, pair, capsys):
    out = tmp_path / "pair.png"
    assert cli.main(["render", str(pair), "--out", str(out), "--size", "96x64", "--seconds", "0.2", "--wind", "20",
                     "--quiet"]) == 0
    assert "pair after 0.2 s" in capsys.readouterr().out
    img = iio.imread(out)
    assert img.shape == (64, 96, 3) and img.std() > 5
    assert cli.main(["render", str(pair), "--paper", "--out", str(tmp_path / "x.png"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the paper's model takes one tree" in err and not (tmp_path / "x.png").exists()


def test_the_command_line_exports_a_scene_that_plays_back(tmp_path, pair, capsys):
    out = tmp_path / "pair.glb"
    assert cli.main(["export", str(pair), "--seconds", "1", "--fps", "10", "--wind", "20", "--out", str(out),
                     "--quiet"]) == 0
    assert validate(out)["numErrors"] == 0
    scene = ta.load_scene(pair)
    skel = skeleton(scene)
    doc, blob = load(out)
    assert len(doc.skins[0].joints) == skel.count == 1 + 2 * 10 + int(np.sum(scene.object_count[scene.kind == "blade"] - 1))
    sim = ta.Simulation(scene, wind=ta.WindField(speed=20.0))
    frames = [sim.positions.copy() for _ in scripted.frames(sim, 10, 10, [])]
    for k in (5, 9):
        baked = joint_world_positions(doc, blob, k)[1:]
        assert np.max(np.linalg.norm(baked - frames[k][skel.joint_node[1:]], axis=1)) < 1e-3


def test_the_viewer_opens_a_scene_file(pair, tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)  # headless: nothing may need a display
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    win = HeadlessWindow(W, H)
    try:
        v = Viewer(win, ta.load_preset("beam"), wind_speed=5.0, show_panel=False)
        try:
            win.connect(v)
            assert v.frame(DT)
            before = v.read_pixels()
            assert v.open_file(str(pair)) and v.messages[-1] == f"loaded {pair}"
            assert isinstance(v.tree, ta.Scene) and v.tree.n_trees == 4 and v.sim.model == "tree"
            v.frame_camera()
            for _ in range(3):
                assert v.frame(DT)
            assert v.ctx.error == "GL_NO_ERROR" and changed(v.read_pixels(), before).mean() > 0.01
            assert v.save_preset(tmp_path / "s.toml") is None and "is a scene of 4 trees" in v.messages[-1]
            v.set_model("tree")
            with pytest.raises(ValueError, match="paper's model takes one tree"):
                v.set_model("paper")
        finally:
            v.release()
    finally:
        win.close()
