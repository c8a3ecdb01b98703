"""The turf leaned by the simulated wind (render/turf.py, turf.frag), measured in real renders
through EGL: the ground brightens or darkens with the wind's speed over it, and the pattern
travels downwind at the wind's speed (a gust seen crossing a meadow)."""

from __future__ import annotations

from importlib.resources import files

import numpy as np
import pytest

import treeanim as ta
from conftest import rest_pose
from treeanim.model.load import load_tree
from treeanim.physics.wind import WindField
from treeanim.render.camera import OrbitCamera
from treeanim.render.scene import Scene
from treeanim.render.turf import LEAN_45, LEAN_EXPONENT, TURF_HEIGHT

SIDE = 240
#: Looking down on the ground round the tree, 29 m across, the wind along +x (image right).
CAMERA = OrbitCamera(target=(0.0, 0.0, 0.0), distance=40.0, azimuth=0.0, elevation=89.0)
#: The sun upwind: blades the wind leans over turn their length to it, and light up.
SUN = (-0.6, 0.75, 0.0)


def luminance(img):
    return img.astype(float) @ np.array([0.2126, 0.7152, 0.0722])


@pytest.fixture(scope="module")
def shots(offscreen, tree):
    """``shot(wind, t)``: the luminance of the view at time ``t`` with ``wind`` on the turf."""
    size = offscreen.width, offscreen.height
    offscreen.resize(SIDE, SIDE)
    offscreen.load(tree, scene=Scene(shadow=False, sun_direction=SUN))

    def shot(wind, t):
        offscreen.update(*rest_pose(tree), wind=wind, time=t)
        return luminance(offscreen.render(CAMERA))

    yield shot
    offscreen.resize(*size)


def gale(**settings):
    wind = WindField.from_preset("gale", **settings)
    wind.canopy_height = 2.5   # a young woodland's
    return wind


def test_the_turf_is_brighter_or_darker_where_the_gusts_blow_than_in_the_lulls(shots):
    still = shots(None, 0.0)
    wind = gale()
    gain = shots(wind, 5.0) / np.maximum(still, 1.0)   # each pixel's, against the still ground
    # Ground points on a lattice in view, where they fall on the screen and the wind over them.
    x, z = np.meshgrid(np.arange(-13.0, 13.5, 0.5), np.arange(-13.0, 13.5, 0.5))
    ground = np.column_stack([x.ravel(), np.zeros(x.size), z.ravel()])
    px = np.rint(CAMERA.project(ground, SIDE, SIDE)[:, :2]).astype(int)
    inside = np.all((px >= 0) & (px < SIDE), axis=1)
    assert inside.mean() > 0.9
    along = wind.sample(ground + [0.0, TURF_HEIGHT, 0.0], 5.0)[inside, 0]   # the gusts' component
    g = gain[px[inside, 1], px[inside, 0]]
    gust, lull = along > np.percentile(along, 75), along < np.percentile(along, 25)
    assert g[gust].mean() - g[lull].mean() > 0.05, (g[gust].mean(), g[lull].mean())
    assert np.corrcoef(along, g)[0, 1] > 0.7


def test_the_pattern_travels_downwind_at_the_wind_speed(shots):
    still = shots(None, 0.0)
    wind, dt = gale(), 0.25
    a, b = shots(wind, 5.0) - still, shots(wind, 5.0 + dt) - still
    per_metre = CAMERA.project(np.array([[1.0, 0.0, 0.0]]), SIDE, SIDE)[0, 0] - SIDE / 2
    shifts = np.arange(0, 90, 2)
    corr = [np.corrcoef(a[:, : SIDE - s].ravel(), b[:, s:].ravel())[0, 1] for s in shifts]
    travel = shifts[int(np.argmax(corr))] / per_metre / dt   # m/s
    assert max(corr) > 0.3
    assert travel == pytest.approx(wind.speed, rel=0.2)


def test_no_wind_leaves_the_ground_as_it_was(shots):
    calm = WindField.from_preset("calm", speed=0.0)
    assert np.array_equal(shots(None, 0.0), shots(calm, 3.0))


def test_the_turf_leans_as_the_meadows_simulated_blades_do():
    """The turf's law of lean against the meadow's blades simulated in a steady gale over a
    young woodland."""
    tree = load_tree(files("treeanim.presets") / "scenes" / "plants" / "meadow.toml")
    sim = ta.Simulation(tree, wind=gale(turbulence=0.0, gust_strength=0.0))
    base, tip = tree.object_start, tree.object_start + tree.object_count - 1

    def lean(P):
        d = P[tip] - P[base]
        return np.degrees(np.arctan2(d[:, 0], d[:, 1]))

    leans = []
    for k in range(120):   # 4 s; the last 2 s averaged
        sim.step(1 / 30)
        if k >= 60:
            leans.append(np.mean(lean(sim.positions) - lean(sim.rest_positions)))
    blades = np.mean(leans)
    U = sim.wind.sample(np.array([[0.0, TURF_HEIGHT, 0.0]]), sim.time)[0, 0]
    assert blades == pytest.approx(np.degrees(np.arctan((U / LEAN_45) ** LEAN_EXPONENT)), abs=5.0)
