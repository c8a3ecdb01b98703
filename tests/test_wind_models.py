"""The wind models behind one base and a registry (issue 27; docs/design.md §15): every
registered model samples, round-trips its settings and refuses another model's; a model
registered here (the design doc's own example) works with the Simulation and the command line."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path
from typing import Annotated

import numpy as np
import pytest

import treeanim as ta
from treeanim.model.declare import Param, SettingError, default_of, settings
from treeanim.physics.wind import WIND_MODELS, PaperWind, PhysicalWind, WindField, WindParams, register_wind_model

DESIGN = Path(__file__).resolve().parents[1] / "docs" / "design.md"
MODELS = list(WIND_MODELS)  # the package's own, before any test registers one


@pytest.fixture
def registry():
    """WIND_MODELS as it was, after the test."""
    before = dict(WIND_MODELS)
    yield WIND_MODELS
    WIND_MODELS.clear()
    WIND_MODELS.update(before)


def design_example() -> str:
    """The python block of docs/design.md's "Adding a wind model"."""
    text = DESIGN.read_text(encoding="utf-8")
    section = text[text.index("**Adding a wind model**"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def shear_wind(registry) -> type[WindField]:
    """The design doc's example, run: its ShearWind class, registered as 'shear'."""
    namespace: dict = {"__name__": "design_example"}
    exec(compile(design_example(), str(DESIGN), "exec", dont_inherit=True), namespace)  # noqa: S102 - the doc's own code
    return namespace["ShearWind"]


def points(k: int = 300) -> np.ndarray:
    p = np.random.default_rng(5).uniform((-8.0, 0.0, -8.0), (8.0, 14.0, 8.0), (k, 3))
    return np.concatenate([p, [[1e9, 3.0, -1e9], [0.0, 1e6, 0.0], [0.0, -3.0, 0.0]]])


def changed(param: Param, default):
    """A valid value of a setting other than its default."""
    if param.integer:
        return default + 1
    if default is None:  # automatic: an explicit value
        return min(max(10.0 * param.lo, 1.0), param.hi)
    if math.isfinite(param.hi):
        return default + 0.25 * (param.hi - default)
    return default + 1.0


def all_changed(cls) -> dict:
    fields = {f.name: f.default for f in dataclasses.fields(cls.Params)}
    return {name: changed(p, fields[name]) for name, p in cls.parameters().items()}


def test_the_package_registers_the_physical_and_the_papers_wind():
    assert WIND_MODELS["physical"] is PhysicalWind and WIND_MODELS["paper"] is PaperWind
    assert type(WindField(speed=3.0)) is PhysicalWind  # the default
    assert type(ta.WindField(model="paper", grid=16)) is PaperWind
    assert isinstance(WindField.from_preset("gale"), PhysicalWind)
    with pytest.raises(ValueError, match="model"):
        PaperWind(model="physical")


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("defaults", [True, False])
def test_every_model_samples_finite_wind_of_the_right_shape(model, defaults):
    cls = WIND_MODELS[model]
    own = {} if defaults else all_changed(cls)
    wind = WindField(model=model, direction=(1.0, 0.0, -0.5), **own)
    p = points()
    for t in (0.0, 1.7, -40.0, 1e9):
        u = wind.sample(p, t)
        assert u.shape == (len(p), 3) and u.dtype == np.float64
        assert np.all(np.isfinite(u))
    assert np.abs(wind.sample(p[:300], 2.0)).max() > 0.1 * wind.speed  # wind, not zeros
    assert wind.sample([0.0, 5.0, 0.0], 0.0).shape == (1, 3)
    assert wind.sample(np.empty((0, 3)), 0.0).shape == (0, 3)
    wind.speed = 0.0
    assert not wind.sample(p, 3.0).any()


@pytest.mark.parametrize("model", MODELS)
def test_settings_round_trip(model):
    cls = WIND_MODELS[model]
    own = all_changed(cls)
    wind = WindField(model=model, direction=(2.0, 0.0, 1.0), **own)
    kw = wind.settings()
    assert kw["model"] == model and np.array_equal(kw["direction"], [2.0, 0.0, 1.0])
    assert {k: v for k, v in kw.items() if k not in ("model", "direction")} == own
    copy = WindField(**kw)
    assert type(copy) is cls and np.array_equal(copy.settings().pop("direction"), kw.pop("direction"))
    assert {k: v for k, v in copy.settings().items() if k != "direction"} == kw
    p = points()
    for t in (0.0, 3.3, 120.0):
        np.testing.assert_array_equal(copy.sample(p, t), wind.sample(p, t))
    # set one at a time through the properties: the same settings
    other = WindField(model=model, direction=(2.0, 0.0, 1.0))
    for name, value in own.items():
        setattr(other, name, value)
    assert {k: v for k, v in other.settings().items() if k != "direction"} == kw


@pytest.mark.parametrize("model", MODELS)
def test_a_setting_of_another_model_is_refused_in_one_line(model):
    cls = WIND_MODELS[model]
    foreign = {name: (m, p) for m, c in WIND_MODELS.items() if m != model
               for name, p in c.parameters().items() if name not in cls.parameters()}
    assert foreign, "the two models share every setting?"
    wind = WindField(model=model, seed=4)
    p = points(50)
    before = wind.sample(p, 0.5)
    for name, (owner, param) in foreign.items():
        value = changed(param, default_of(WIND_MODELS[owner].Params, name))
        for attempt in (lambda: WindField(model=model, **{name: value}), lambda: setattr(wind, name, value)):
            with pytest.raises(ValueError, match=f"^{name}: a setting of the {owner} wind model, not of the {model} one") as e:
                attempt()
            assert "\n" not in str(e.value)
        assert not hasattr(wind, name)
    with pytest.raises(ValueError, match=f"^colour: not a setting of the {model} wind model"):
        wind.colour = "blue"
    np.testing.assert_array_equal(wind.sample(p, 0.5), before)


@pytest.mark.parametrize("model", MODELS)
def test_a_bad_value_is_refused_by_its_declaration_and_the_old_one_kept(model):
    wind = WindField(model=model)
    for name, param in WIND_MODELS[model].parameters().items():
        old = getattr(wind, name)
        bad = param.hi + 1 if math.isfinite(param.hi) else math.nan
        with pytest.raises(SettingError, match=f"^{name}: expected "):
            setattr(wind, name, bad)
        assert getattr(wind, name) == old


def test_the_design_docs_example_is_a_working_wind_model(registry):
    shear = shear_wind(registry)
    assert WIND_MODELS["shear"] is shear and list(shear.parameters()) == ["speed", "shear"]
    wind = ta.WindField(model="shear", speed=8.0, shear=0.2)
    assert type(wind) is shear and wind.shear == 0.2
    wind.fit(((-1.0, 0.0, -1.0), (1.0, 10.0, 1.0)))
    u = wind.sample([[0.0, 10.0, 0.0], [0.0, 2.5, 0.0]], 0.0)
    np.testing.assert_allclose(u, [[8.0, 0.0, 0.0], [8.0 * 0.25**0.2, 0.0, 0.0]], rtol=1e-12)
    with pytest.raises(SettingError, match=r"^shear: expected a number in \[0, 1\], got 2.0"):
        wind.shear = 2.0
    with pytest.raises(ValueError, match="^seed: a setting of the (paper and physical|physical and paper)"):
        ta.WindField(model="shear", seed=3)
    copy = ta.WindField(**wind.settings())
    assert type(copy) is shear and copy.shear == 0.2 and copy.speed == 8.0


@pytest.mark.parametrize("sim_model", ["tree", "paper"])
def test_a_model_registered_in_a_test_drives_the_simulation(registry, sim_model):
    shear_wind(registry)
    tree = ta.load_preset("beam")
    wind = ta.WindField(model="shear", speed=20.0, direction=(0.0, 0.0, 1.0))
    sim = ta.Simulation(tree, wind=wind, model=sim_model)
    top = float(tree.rest_positions[:, 1].max())
    assert wind.bounds[1, 1] == pytest.approx(top)  # fitted to the tree
    tip = tree.object_start[0] + tree.object_count[0] - 1
    for _ in range(60):
        sim.step(1 / 60)
    moved = sim.positions[tip] - tree.rest_positions[tip]
    assert moved[2] > 1e-3 and abs(moved[0]) < 0.1 * moved[2]  # downwind (+z), not across
    calm = ta.Simulation(tree, wind=ta.WindField(model="shear", speed=0.0), model=sim_model)
    for _ in range(60):
        calm.step(1 / 60)
    np.testing.assert_allclose(calm.positions[tip], tree.rest_positions[tip], atol=1e-9)


def test_the_command_line_offers_a_registered_model(registry):
    from treeanim import cli
    from treeanim.errors import UsageError

    shear_wind(registry)
    parser = cli.build_parser()
    args = parser.parse_args(["render", "beam", "--wind-model", "shear", "--wind", "7", "--seed", "3", "--out", "x.png"])
    _, sim = cli.make_simulation(args)
    assert sim.wind.model == "shear" and sim.wind.speed == 7.0  # --seed is not the shear wind's
    args = parser.parse_args(["render", "beam", "--wind-model", "shear", "--turbulence", "0.2", "--out", "x.png"])
    with pytest.raises(UsageError, match="^turbulence: a setting of the"):
        cli.make_simulation(args)
    # a named wind is the physical model's: asked of another it is refused, not swapped for it
    args = parser.parse_args(["render", "beam", "--wind-model", "shear", "--wind-preset", "gale", "--out", "x.png"])
    with pytest.raises(UsageError, match="^--wind-preset: the named winds are for the physical wind model, not the shear"):
        cli.make_simulation(args)


def test_registering_checks_the_class(registry):
    @settings("")
    class Own(WindParams):
        gain: Annotated[float, Param(0.0, 10.0, help="A gain.")] = 1.0

    with pytest.raises(TypeError, match="must subclass WindField"):
        register_wind_model("plain")(type("Plain", (), {}))

    class Undeclared(WindParams):  # no @settings: its fields would be lost
        pass

    with pytest.raises(TypeError, match=r"@settings\(''\)"):
        type("Bad", (WindField,), {"Params": Undeclared, "_sample": lambda self, p, t, out: None})
    @settings("")
    class Clash(WindParams):
        frame: Annotated[float, Param(0.0, 1.0)] = 0.0

    with pytest.raises(TypeError, match="frame would hide WindField's own"):
        type("Hiding", (WindField,), {"Params": Clash, "_sample": lambda self, p, t, out: None})
    with pytest.raises(ValueError, match="already registered"):
        register_wind_model("paper")(type("Again", (WindField,), {"Params": Own, "_sample": lambda *a: None}))
    assert WIND_MODELS["paper"] is PaperWind
