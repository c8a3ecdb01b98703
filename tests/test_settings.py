"""The physics settings are declared once (treeanim.model.params): whatever can be set can be
saved and loaded back, equal; what the declaration refuses, every way in refuses in one line
naming the setting, the value and the allowed range."""

from __future__ import annotations

import argparse
import dataclasses
import functools
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import treeanim as ta
from treeanim import PresetError
from treeanim.app.save import physics_toml, save_preset
from treeanim.model.params import MODE_PARAMS, PARAMS, ModeRange, PhysicsParams, SeasonModes, SettingError
from treeanim.options import physics_setting

TREE = ta.load_preset("small_cherry")  # branches and leaves: every kind's range it has is used


def ends(p):
    """The smallest and the largest value the declaration ``p`` allows."""
    return (math.nextafter(p.lo, math.inf) if p.lo_open else p.lo), p.hi


def beyond(p):
    """Values just outside ``p``, and ones no number check lets through."""
    return [p.lo if p.lo_open else math.nextafter(p.lo, -math.inf), math.nextafter(p.hi, math.inf),
            math.inf, math.nan]


@functools.cache
def simulations():
    """A simulation of the tree on each model (each test sets the whole physics, so none sees
    another's)."""
    return [ta.Simulation(TREE, model=m) for m in ("tree", "paper")]


def set_everywhere(physics):
    for sim in simulations():
        sim.physics = physics  # the setter takes it
        assert sim.physics == physics


def saved_and_loaded(tmp_path, physics, name="mine.toml"):
    return ta.load_tree(save_preset(tmp_path / name, TREE, physics)).physics


SCALAR_ENDS = [(name, x) for name, p in PARAMS.items() for x in ends(p)]


@pytest.mark.parametrize("name, value", SCALAR_ENDS, ids=[f"{n}={v:g}" for n, v in SCALAR_ENDS])
def test_every_setting_at_its_bounds_is_set_saved_and_loaded_back_equal(tmp_path, name, value):
    physics = dataclasses.replace(TREE.physics, **{name: value})
    assert getattr(physics, name) == value
    set_everywhere(physics)
    assert saved_and_loaded(tmp_path, physics) == physics  # and so does the preset, exactly


@pytest.mark.parametrize("what", list(MODE_PARAMS))
def test_mode_ranges_at_their_bounds_are_saved_and_loaded_back_equal(tmp_path, what):
    lo, hi = ends(MODE_PARAMS[what])
    p = TREE.physics
    wide = dataclasses.replace(p.summer.branch, **{what: (lo, hi)})
    point = dataclasses.replace(p.winter.leaf, **{what: (hi, hi)})
    physics = dataclasses.replace(p, summer=dataclasses.replace(p.summer, branch=wide, blade=wide),
                                  winter=dataclasses.replace(p.winter, leaf=point))
    set_everywhere(physics)
    assert saved_and_loaded(tmp_path, physics) == physics


@pytest.mark.parametrize("name", list(PARAMS))
def test_a_value_beyond_a_bound_is_refused_in_one_line_everywhere(tmp_path, name):
    p = PARAMS[name]
    for bad in beyond(p):
        with pytest.raises(SettingError) as err:
            dataclasses.replace(TREE.physics, **{name: bad})
        msg = str(err.value)
        assert isinstance(err.value, ValueError) and "\n" not in msg
        assert msg == f"physics.{name}: expected a number in {p.interval}, got {bad!r}", msg
        with pytest.raises(argparse.ArgumentTypeError, match=f"physics.{name}: expected a number in"):
            physics_setting(f"{name}={bad!r}")
    # the preset reader says the same, naming the file and the key
    path = tmp_path / "bad.toml"
    path.write_text(open(TREE.source).read().replace("[physics.summer]", f"[physics]\n{name} = 1e300\n\n[physics.summer]"))
    with pytest.raises(PresetError) as err:
        ta.load_tree(path)
    assert str(err.value) == f"{path}: key 'physics.{name}': expected a number in {p.interval}, got 1e+300"


@pytest.mark.parametrize("bad", [True, "1.0", None, [1.0]])
def test_settings_are_numbers_not_anything_float_takes(bad):
    with pytest.raises(SettingError, match="physics.ei_max: expected a number"):
        PhysicsParams(ei_max=bad)


def test_ranges_keep_their_order_and_bounds():
    with pytest.raises(SettingError, match=r"ModeRange.f: expected \[min, max\] with min <= max, got \[2.0, 1.0\]"):
        ModeRange((2.0, 1.0), (0.1, 0.2))
    with pytest.raises(SettingError, match=r"ModeRange.zeta: expected a number in \[0, 1000\], got -0.1"):
        ModeRange((1.0, 2.0), (-0.1, 0.2))
    with pytest.raises(SettingError, match=r"SeasonModes.twig: unknown key; expected one of branch, leaf, blade"):
        SeasonModes(twig=None)
    with pytest.raises(SettingError, match="physics.ei_mac: unknown key"):
        dataclasses.replace(PhysicsParams(), ei_mac=1.0)
    assert ModeRange([1, 2], [0, 0.5]) == ModeRange((1.0, 2.0), (0.0, 0.5))  # as TOML has them
    with pytest.raises(dataclasses.FrozenInstanceError):
        TREE.physics.ei_max = 1.0


@st.composite
def physics(draw):
    """Any PhysicsParams: every scalar anywhere in its range, ranges for every kind."""
    def number(p):
        lo, hi = ends(p)
        return st.floats(lo, hi, allow_nan=False, allow_infinity=False)

    def mode_range():
        f = sorted(draw(st.tuples(number(MODE_PARAMS["f"]), number(MODE_PARAMS["f"]))))
        z = sorted(draw(st.tuples(number(MODE_PARAMS["zeta"]), number(MODE_PARAMS["zeta"]))))
        return ModeRange(tuple(f), tuple(z))

    scalars = {name: draw(number(p)) for name, p in PARAMS.items()}
    seasons = {s: SeasonModes(branch=mode_range(), leaf=mode_range(),
                              blade=mode_range() if draw(st.booleans()) else None)
               for s in ("summer", "winter")}
    return PhysicsParams(**seasons, **scalars)


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(p=physics())
def test_any_physics_is_saved_and_loaded_back_equal(tmp_path, p):
    assert saved_and_loaded(tmp_path, p, "any.toml") == p
    assert ta.load_tree(save_preset(tmp_path / "again.toml", TREE, p)).physics == p  # and from scratch
    text = physics_toml(p)
    assert all(f"{name} = " in text for name in PARAMS)


def test_the_save_keeps_the_presets_comments_and_order(tmp_path):
    original = open(TREE.source).read()
    physics = dataclasses.replace(TREE.physics, twist_c0=0.0)
    text = save_preset(tmp_path / "c.toml", TREE, physics).read_text()
    assert text.startswith(original[: original.index("[physics.summer]")])  # all of it, byte for byte
    assert "[physics]\ntwist_c0 = 0.0\n" in text  # only what differs from the defaults is added
    assert text.index("[physics]") < text.index("[physics.summer]") < text.index("[physics.winter]")


def test_the_panel_and_the_command_line_take_the_declarations():
    from treeanim.app.settings import SETTINGS

    ei = SETTINGS["ei_max"]
    assert (ei.lo, ei.hi, ei.log, ei.label) == (0.0, PARAMS["ei_max"].hi, True, "EI_max")
    assert ei.fmt.endswith("N·m²")
    for kind in ("branch", "leaf", "blade"):
        for what, p in MODE_PARAMS.items():
            s = SETTINGS[f"{what}:{kind}"]
            assert (s.lo, s.hi, s.fmt) == (p.lo, p.hi, p.fmt)
    assert physics_setting("twist-c0=0") == ("twist_c0", 0.0)
    with pytest.raises(argparse.ArgumentTypeError, match="NAME one of ei_max, stiffness_exponent"):
        physics_setting("stiffness=3")


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PARAMS))
def test_every_setting_at_its_bounds_keeps_the_tree_finite_in_a_gale(name):
    """The bounds are what keeps every state finite: each end, on both models, on a tree with
    leaves and on grass, 20 steps in a 30 m/s wind (a leaf density of 1e-200 once gave NaN)."""
    import numpy as np

    for preset in ("small_cherry", "grassland"):
        tree = ta.load_preset(preset)
        for model in ("tree", "paper"):
            for value in ends(PARAMS[name]):
                sim = ta.Simulation(tree, wind=ta.WindField(speed=30.0), model=model)
                sim.physics = dataclasses.replace(tree.physics, **{name: value})
                for _ in range(20):
                    sim.step(1 / 30)
                assert np.isfinite(sim.positions).all(), (preset, model, value)


def test_the_command_line_sets_physics_for_the_run():
    from treeanim import cli

    args = cli.build_parser().parse_args(["info", "beam", "--physics", "ei_max=75", "--physics", "twist_c0=0"])
    tree = cli.load_any(args.preset, args)
    assert (tree.physics.ei_max, tree.physics.twist_c0) == (75.0, 0.0)
    assert tree.physics == dataclasses.replace(ta.load_preset("beam").physics, ei_max=75.0, twist_c0=0.0)


def test_the_command_line_refuses_a_setting_in_one_line(tmp_path):
    import subprocess
    import sys

    res = subprocess.run([sys.executable, "-m", "treeanim", "info", "beam", "--physics", "ei_max=-3"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr.count("\n") == 1 and "physics.ei_max: expected a number in (0, 1e+12], got -3.0" in res.stderr
