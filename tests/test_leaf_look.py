"""Leaves with material (issue 30): the species' leaf maps, light through a lamina, its paler
back, the crown's occlusion and winter's withered leaves, by the pixels of real renders (EGL)."""

from __future__ import annotations

import colorsys

import numpy as np

import treeanim as ta
from conftest import ovate_lamina
from treeanim.model.build import ObjectSpec, assemble
from treeanim.render.camera import OrbitCamera
from treeanim.render.leaf_maps import ALBEDO_SCALE, SIZE, leaf_maps, make_leaf_maps
from treeanim.render.scene import Scene

W, H = 160, 120
LUMA = np.array([0.2126, 0.7152, 0.0722])


def leaf(at, w, length=0.4, parent=0, attach=1):
    """A leaf whose petiole rises 5 cm from ``at``, its lamina facing ``w``."""
    at = np.asarray(at, float)
    return ObjectSpec(np.stack([at, at + (0.0, 0.025, 0.0), at + (0.0, 0.05, 0.0)]), np.full(3, 0.004), "leaf", 2,
                      parent=parent, attach=attach, w=np.asarray(w, float), lamina_length=length)


def one_leaf():
    """A stem and one upright leaf facing +z (its upper face towards a camera at azimuth 0)."""
    stem = ObjectSpec(np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.array([0.01, 0.008]), "branch", 1)
    return assemble([stem, leaf((0.0, 1.0, 0.0), (0.0, 0.0, 1.0))], name="one_leaf", lamina=ovate_lamina(),
                    petiole_sides=4, seed=1, winter_leaves=1)


def render(off, tree, cam, present=None, season=0.0, **scene):
    off.resize(W, H)
    off.load(tree, scene=Scene(shadow=False, haze_distance=1e4, **scene))  # no haze over the leaves
    P = tree.rest_positions
    off.update(P, np.broadcast_to(np.eye(3), (len(P), 3, 3)), present=present)
    return off.render(cam, season=season).astype(float)


def leaf_colour(off, tree, cam, season=0.0, **scene):
    """Mean colour (0–255 sRGB) of the pixels the leaves change, and how many they are."""
    bare = render(off, tree, cam, present=tree.kind != "leaf", season=season, **scene)
    img = render(off, tree, cam, season=season, **scene)
    on = np.abs(img - bare).max(axis=2) > 12
    return img[on].mean(axis=0), int(on.sum())


def facing(azimuth):
    return OrbitCamera(target=(0.0, 1.25, 0.0), distance=1.1, azimuth=azimuth, elevation=0.0)


def test_the_leaf_maps_are_made_once_the_same_each_time_and_show_the_veins():
    lamina = ta.load_preset("small_cherry").lamina
    maps = make_leaf_maps(lamina)
    assert maps.shape == (SIZE, SIZE, 4) and maps.dtype == np.uint8
    np.testing.assert_array_equal(maps, make_leaf_maps(lamina))
    assert leaf_maps(lamina) is leaf_maps(lamina) and not leaf_maps(lamina).flags.writeable
    np.testing.assert_array_equal(leaf_maps(lamina), maps)
    albedo, through = maps[..., 0] * ALBEDO_SCALE / 255.0, maps[..., 1] / 255.0
    mid, blade = SIZE // 2, slice(SIZE // 2 + SIZE // 16, SIZE // 2 + SIZE // 8)  # the midrib; beside it
    rows = slice(SIZE // 8, SIZE // 2)
    assert np.median(albedo[rows, mid]) > 1.25 * np.median(albedo[rows, blade])  # paler veins
    assert np.median(through[rows, mid]) < 0.8 * np.median(through[rows, blade])  # thicker: less light through
    # The side veins: along a line across the blade, the albedo rises and falls several times.
    across = albedo[SIZE // 3, SIZE // 2 + 4:]
    assert np.sum(np.diff((across > np.median(across) * 1.12).astype(int)) == 1) >= 3


def test_a_leaf_lit_from_behind_glows_yellow_green(offscreen):
    tree = one_leaf()
    cam = facing(0.0)
    edge, n = leaf_colour(offscreen, tree, cam, sun_direction=(1.0, 0.3, 0.0))  # grazing: not through it
    glow, m = leaf_colour(offscreen, tree, cam, sun_direction=(0.0, 0.3, -1.0))  # behind it
    assert n > 400 and m > 400
    assert glow @ LUMA > 2.0 * (edge @ LUMA), (glow, edge)
    through = glow - edge  # the light the lamina lets through: green, with yellow's red, little blue
    assert through[1] > through[0] > 0.6 * through[1] and through[2] < 0.3 * through[1], through


def test_the_back_of_a_leaf_is_paler_than_its_front(offscreen):
    tree = one_leaf()
    sun = dict(sun_direction=(0.0, 1.0, 0.0))  # overhead: along the lamina, lighting both faces alike
    front, n = leaf_colour(offscreen, tree, facing(0.0), **sun)
    back, m = leaf_colour(offscreen, tree, facing(180.0), **sun)
    assert n > 400 and m > 400
    assert back @ LUMA > 1.12 * (front @ LUMA), (back, front)
    saturation = [colorsys.rgb_to_hsv(*(c / 255.0))[1] for c in (front, back)]
    assert saturation[1] < saturation[0] - 0.05, saturation


def test_winter_leaves_are_withered_tan_not_red(offscreen):
    tree = one_leaf()
    colour, n = leaf_colour(offscreen, tree, facing(0.0), season=1.0)
    assert n > 400
    hue = 360.0 * colorsys.rgb_to_hsv(*(colour / 255.0))[0]
    assert 28.0 < hue < 60.0 and colour[0] < 1.5 * colour[1], (hue, colour)


def clumps(rng=np.random.default_rng(7)):
    """Two dense clumps of leaves 2.4 m apart at 2 m height, and a lone leaf in the gap between
    them (where the crown's centre is), all facing +z. Returns the tree and the leaves' places:
    0 the lone one, 1 inside a clump, 2 on a clump's outside."""
    specs = [ObjectSpec(np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 2.0, 0.0]]), np.array([0.1, 0.08, 0.06]),
                        "branch", 1)]
    place = [0]
    specs.append(leaf((0.0, 1.95, 0.0), (0.0, 0.0, 1.0), length=0.2, attach=2))
    for side in (-1.0, 1.0):
        specs.append(ObjectSpec(np.array([[0.0, 2.0, 0.0], [0.6 * side, 2.0, 0.0], [1.2 * side, 2.0, 0.0]]),
                                np.array([0.04, 0.03, 0.02]), "branch", 2, parent=0, attach=2))
        b = len(specs) - 1
        for _ in range(400):
            d = rng.normal(size=3)
            r = 0.5 * rng.random() ** (1 / 3)
            at = np.array([1.2 * side, 1.95, 0.0]) + r * d / np.linalg.norm(d)
            specs.append(leaf(at, (0.0, 0.0, 1.0), length=0.2, parent=b, attach=2))
            place.append(1 if r < 0.2 else 2 if r > 0.42 else 3)
    tree = assemble(specs, name="clumps", lamina=ovate_lamina(), petiole_sides=4, seed=2, winter_leaves=1)
    where = np.full(tree.n_objects, -1)
    where[tree.kind == "leaf"] = place
    return tree, where


def test_the_crown_is_darker_inside_than_outside_and_a_leaf_in_a_gap_is_open(offscreen):
    tree, where = clumps()
    sun = (0.0, 1.0, 0.0)  # overhead, along the laminas: sky light only, what the occlusion shades
    cam = OrbitCamera(target=(0.0, 2.0, 0.0), distance=4.5, azimuth=0.0, elevation=0.0)
    bare = render(offscreen, tree, cam, present=tree.kind != "leaf", sun_direction=sun)
    shade = []
    for k in range(3):  # each group of leaves alone: the crown's occlusion was made once, from them all
        img = render(offscreen, tree, cam, present=(tree.kind != "leaf") | (where == k), sun_direction=sun)
        on = np.abs(img - bare).max(axis=2) > 12
        assert on.sum() > 20, (k, on.sum())
        shade.append(float((img[on] @ LUMA).mean()))
    lone, inside, outside = shade
    assert inside < 0.85 * outside, shade
    assert lone > 1.1 * inside, shade
