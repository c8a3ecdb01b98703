"""The command line's option types (argparse ``type=`` callables that refuse bad input with
one clear line) and the option groups several commands share (wind, season, scene, timing)."""

from __future__ import annotations

import argparse

from .driver import step_for
from .errors import InputError, UsageError

#: Upper bound of times, rates and counts on the command line: large enough for any real use,
#: small enough that products of them stay finite and allocations sane.
LIMIT = 1e6
#: Most frames (or samples) one command may produce.
MAX_FRAMES = 1_000_000
#: Most simulation steps one command may take (hours of work at a few ms a step).
MAX_STEPS = 2_000_000
#: The help of every command's tree argument.
PRESET_HELP = ("a preset's or a scene's name (see 'treeanim list'), a preset or scene .toml file, or a TreeQSM "
               "cylinder model: a .txt or .csv table or a .mat file (see --leaves)")
#: How ``--pull``, ``--drag`` and ``trace --object`` name an object, for their help.
OBJECT_HELP = ("OBJECT is an object's number, root first and level by level (0 is the trunk, or a meadow's "
               "first blade); 'treeanim info PRESET --objects' lists them with their kind, length and tip")


def shown(text: str, width: int = 40) -> str:
    """``text`` as an error message quotes it: its repr, cut to ``width`` characters."""
    return repr(text) if len(text) <= width else repr(text[:width]) + f"… ({len(text):,} characters)"


def number(kind, lo: float, hi: float, lo_open: bool):
    """An argparse type: a ``kind`` (int or float) in (lo, hi] or [lo, hi]."""
    fmt = (lambda x: f"{int(x):,}") if kind is int else (lambda x: f"{x:g}")
    noun = "integer" if kind is int else "number"
    if lo_open and lo == 0:
        what = f"a positive {noun} up to {fmt(hi)}"
    else:
        what = f"{'an' if kind is int else 'a'} {noun} in [{fmt(lo)}, {fmt(hi)}]"

    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            value = float("nan")
        if not ((value > lo) if lo_open else (value >= lo)) or not value <= hi:
            raise argparse.ArgumentTypeError(f"expected {what}, got {shown(text)}")
        return value

    return parse


def positive(kind, hi: float = LIMIT):
    """An argparse type: a ``kind`` (int or float) in (0, ``hi``]."""
    return number(kind, 0, hi, lo_open=True)


non_negative = number(float, 0, LIMIT, lo_open=False)


#: Joint budgets of ``export --target``, the joints one skin holds for each engine: Unreal
#: imports 256 bones per skeletal mesh section by default; Unity and Godot take more, but their
#: editors slow down (Godot's has frozen on skeletons of 600–760 bones); three.js (``web``)
#: keeps its bone matrices in a texture, and 1,024 keeps a large tree's animation CPU low.
JOINT_TARGETS = {"unreal": 256, "unity": 256, "godot": 256, "web": 1024}


def joint_budget(text: str) -> int | None:
    """``export --joints``: a whole number >= 2 (the root joint and one more), or ``all`` (None).

    Raises
    ------
    ValueError
        One line, for anything else.
    """
    if str(text).strip().lower() == "all":
        return None
    try:
        n = int(text)
    except ValueError:
        raise ValueError(f"{text!r}: expected a whole number of joints >= 2, or 'all'") from None
    if n < 2:
        raise ValueError(f"{n}: at least 2 joints (the root joint and one more), or 'all'")
    return n


def checked(parse):
    """An argparse type from a parser that raises ValueError with a clear message."""

    def typed(text: str):
        try:
            return parse(text)
        except ValueError as e:
            raise argparse.ArgumentTypeError(str(e)) from None

    typed.__name__ = parse.__name__
    return typed


def size(text: str) -> tuple[int, int]:
    """An argparse type: ``WxH`` pixels (:func:`treeanim.offline.target.parse_size`)."""
    from treeanim.offline.target import parse_size

    return checked(parse_size)(text)


def vector(what: str, force: bool = False):
    """An argparse type: X,Y,Z (a force: of at most the simulation's largest pull)."""
    from treeanim.scripted import parse_force, parse_vector

    parse = parse_force if force else parse_vector
    return checked(lambda text: parse(text, what))


def pull(text: str):
    """An argparse type: ``OBJECT:FX,FY,FZ@T0-T1`` (:func:`treeanim.scripted.parse_pull`)."""
    from treeanim.scripted import parse_pull

    return checked(parse_pull)(text)


def drag(text: str):
    """An argparse type: ``OBJECT[@S]:X,Y,Z@T0-T1`` (:func:`treeanim.scripted.parse_drag`)."""
    from treeanim.scripted import parse_drag

    return checked(parse_drag)(text)


def wind_speed(text: str) -> float:
    """An argparse type: a wind speed from 0 to the wind field's largest, m/s."""
    from treeanim.physics.wind import MAX_SPEED

    return number(float, 0, MAX_SPEED, lo_open=False)(text)


def physics_setting(text: str) -> tuple[str, float]:
    """An argparse type: ``NAME=VALUE``, a physics setting (:data:`treeanim.model.params.PARAMS`)
    checked by its declaration."""
    from treeanim.model.params import PARAMS, PhysicsParams, SettingError

    name, sep, value = text.partition("=")
    name = name.strip().replace("-", "_")
    if not sep or name not in PARAMS:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE with NAME one of {', '.join(PARAMS)}, got {shown(text)}")
    try:
        x = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"physics.{name}: expected {PARAMS[name].expected}, got {value.strip()!r}") from None
    try:
        PhysicsParams(**{name: x})
    except SettingError as e:
        raise argparse.ArgumentTypeError(str(e)) from None
    return name, x


def add_season_option(p: argparse.ArgumentParser) -> None:
    """--season, --leaves, --modes and --physics, for every command that builds a tree."""
    from treeanim.model.params import PARAMS
    from treeanim.model.qsm import SPECIES

    p.add_argument("--season", type=number(float, 0, 1, lo_open=False), default=0.0, help="0 = summer … 1 = winter (default 0)")
    p.add_argument("--leaves", default=None, metavar="SPECIES[:PER_METRE]",
                   help=f"a TreeQSM model's leaves along its twigs: none (default) or {', '.join(SPECIES)}, "
                   "optionally with leaves per metre of twig (e.g. cherry:80)")
    p.add_argument("--modes", choices=["paper", "physical"], default=None,
                   help="the paper's model's modal f and zeta: paper (Eqs. 20-22; the presets' default) or "
                   "physical (beam theory; TreeQSM models' default)")
    names = ", ".join(f"{k} ({p.unit + ' ' if p.unit else ''}{p.interval})" for k, p in PARAMS.items())
    p.add_argument("--physics", type=physics_setting, action="append", default=[], metavar="NAME=VALUE",
                   help=f"set one of the preset's physics parameters (repeatable; e.g. ei_max=3e4): {names}")


def add_precision_option(p: argparse.ArgumentParser) -> None:
    """``export --precision``: compact (the default) or full (:mod:`treeanim.compact`)."""
    from treeanim.compact import PRECISIONS, TOLERANCE

    p.add_argument("--precision", choices=PRECISIONS, default=PRECISIONS[0],
                   help="compact (default): positions, normals and rotation keys quantised to 16 and 8 bits, and "
                   f"each joint's keys thinned where its motion allows (no joint's keys move a vertex more than "
                   f"{TOLERANCE * 1000:g} mm; the command prints the measured error); full: float32 and every key (glTF "
                   "files)")


def add_wind_speed_options(p: argparse.ArgumentParser, wind: float = 5.0) -> None:
    """--wind and --wind-preset (the viewer's and the offline commands' wind)."""
    from treeanim.physics.wind import WIND_PRESETS

    names = ", ".join(f"{k} (Beaufort {v['beaufort']}, {v['speed']:g} m/s)" for k, v in WIND_PRESETS.items())
    p.add_argument("--wind", type=wind_speed, default=None, metavar="SPEED",
                   help=f"mean wind speed at the canopy top, m/s (default {wind:g}, or the preset's; 0 = calm)")
    p.add_argument("--wind-preset", choices=list(WIND_PRESETS), default=None, metavar="NAME",
                   help=f"a named wind: {names}; --wind (and --turbulence where it exists) override its values")


def add_wind_options(p: argparse.ArgumentParser, wind: float = 5.0) -> None:
    """Wind, season and seed options (the scene around the tree)."""
    from treeanim.physics.wind import WIND_MODELS

    add_wind_speed_options(p, wind)
    p.add_argument("--wind-model", choices=list(WIND_MODELS), default=None,
                   help="physical (default: turbulence in metres carried downwind, gusts, canopy profile) "
                   "or paper (Hu, Chiba & He 2012, Eqs. 13-18; the default with --paper)")
    p.add_argument("--wind-dir", type=vector("direction"), default=(1.0, 0.0, 0.0), metavar="X,Y,Z",
                   help="wind direction; needs a horizontal part (default 1,0,0)")
    p.add_argument("--turbulence", type=number(float, 0, 2, lo_open=False), default=None, metavar="T",
                   help="physical: turbulence intensity at the canopy top in [0, 1] (default 0.3); "
                   "paper: lambda of Eq. 17 in [1, 2] (default 1.5)")
    add_season_option(p)
    p.add_argument("--seed", type=number(int, 0, 2**32 - 1, lo_open=False), default=0,
                   help="seed of the wind and the modal noise (default 0)")
    p.set_defaults(wind_default=wind)


def wind_settings(args) -> dict:
    """WindField keyword arguments from :func:`add_wind_options` (speed 0 means calm: no field);
    ``--seed`` goes to a wind model that has a seed."""
    from treeanim.physics.wind import wind_model, wind_preset

    model = getattr(args, "wind_model", None)
    kw = dict(model=model or ("paper" if getattr(args, "paper", False) else "physical"))
    if getattr(args, "wind_preset", None):
        try:
            kw.update(wind_preset(args.wind_preset, kw["model"]))
        except ValueError as e:
            raise UsageError(f"--wind-preset: {e}") from None
    kw.setdefault("speed", args.wind_default)
    if args.wind is not None:
        kw["speed"] = args.wind
    if getattr(args, "turbulence", None) is not None:
        kw["turbulence"] = args.turbulence
    kw["direction"] = args.wind_dir
    if "seed" in wind_model(kw["model"]).parameters():
        kw["seed"] = args.seed
    return kw


def add_scene_options(p: argparse.ArgumentParser, seconds: float | None = 5.0, fps: float = 30.0,
                      seconds_help: str | None = None) -> None:
    """Options shared by the offline commands: the preset, timing, wind, season and pulls."""
    p.add_argument("preset", help=PRESET_HELP)
    p.add_argument("--seconds", type=positive(float), default=seconds,
                   help=seconds_help or f"duration in seconds (default {seconds:g})")
    p.add_argument("--fps", type=positive(float), default=fps, help=f"frames per second (default {fps:g})")
    add_wind_options(p)
    p.add_argument("--pull", type=pull, action="append", default=[], metavar="OBJECT:FX,FY,FZ@T0-T1",
                   help="pull OBJECT's tip with a world force in newtons from T0 to T1 s, then let go; repeatable. "
                   + OBJECT_HELP)
    p.add_argument("--drag", type=drag, action="append", default=[], metavar="OBJECT[@S]:X,Y,Z@T0-T1",
                   help="drag OBJECT's tip (or the point at fraction S of its length) toward the world point "
                   "X,Y,Z (m) from T0 to T1 s, then let go; repeatable, one at a time; the tree model only. "
                   + OBJECT_HELP)
    add_model_option(p)


def add_model_option(p: argparse.ArgumentParser) -> None:
    """--paper: the simulation's model (the tree model by default)."""
    p.add_argument("--paper", action="store_true",
                   help="the paper's model (Hu, Chiba & He 2012): every object on its own, driven by modal "
                   "oscillators, in the paper's wind field (default: the tree model, the whole tree as one "
                   "structure, in the physical wind)")


def model(args) -> str:
    """The Simulation's ``model`` from :func:`add_model_option`."""
    return "paper" if getattr(args, "paper", False) else "tree"


def scheduled(args) -> list:
    """The --pull and --drag items of :func:`add_scene_options`, for :func:`treeanim.scripted.frames`."""
    return [*getattr(args, "pull", []), *getattr(args, "drag", [])]


def check_frames(seconds: float, fps: float) -> int:
    """The number of frames ``seconds`` at ``fps`` give; UsageError beyond :data:`MAX_FRAMES`,
    or beyond :data:`MAX_STEPS` simulation steps (the frame driver's, :func:`~treeanim.driver.step_for`)."""
    n = seconds * fps
    if n > MAX_FRAMES:
        raise UsageError(f"--seconds {seconds:g} at --fps {fps:g} is {n:.3g} frames; at most {MAX_FRAMES:,}")
    steps = seconds / step_for(fps)
    if steps > MAX_STEPS:
        raise UsageError(f"--seconds {seconds:g} takes {steps:.3g} simulation steps; at most {MAX_STEPS:,} "
                         f"(about {MAX_STEPS / 3600 / 60:.0f} hours of simulated time at 60 steps a second)")
    return int(round(n))


def finite(text: str) -> float:
    """An argparse type: any finite number."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if value != value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {shown(text)}")
    return value


#: MSAA sample counts a GL implementation may offer (more are clamped to what it has).
SAMPLES = (0, 1, 2, 4, 8, 16)


def samples(text: str) -> int:
    """An argparse type: an MSAA sample count of :data:`SAMPLES`."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value not in SAMPLES:
        raise argparse.ArgumentTypeError(f"expected one of {', '.join(map(str, SAMPLES))}, got {shown(text)}")
    return value


# ---------------------------------------------------------------------------- what commands build from their options
def make_simulation(args):
    """The tree and a Simulation set up from :func:`treeanim.options.add_scene_options`."""
    import treeanim as ta
    from treeanim.scripted import check_pulls

    tree = load_any(args.preset, args)
    try:
        check_pulls(scheduled(args), tree.n_objects, model(args))
        wind = None
        kw = wind_settings(args)
        if kw["speed"] > 0:
            wind = ta.WindField(**kw)
        sim = ta.Simulation(tree, wind=wind, season=args.season, seed=args.seed, model=model(args))
    except ValueError as e:
        raise UsageError(str(e)) from None
    return tree, sim


def output_path(text: str, suffixes: tuple[str, ...], option: str = "--out"):
    """Check an output path: a known extension and a folder where files can really be created."""
    from pathlib import Path

    from treeanim.offline.target import check_file

    path = Path(text)
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"{option} {text}: unknown extension {path.suffix or '(none)'!r}; expected {', '.join(suffixes)}")
    try:
        check_file(path, text)
    except InputError as e:
        raise UsageError(str(e).replace("--out ", f"{option} ", 1)) from None
    return path


def load_any(name_or_path: str, args=None):
    """A preset or a scene by name, a preset or scene TOML file or a TreeQSM model (.txt, .csv,
    .mat) by path, with ``args``' --leaves (QSM only), --modes and --physics."""
    from treeanim.model.load import load_named

    return with_settings(load_named(name_or_path, leaves=getattr(args, "leaves", None)), args)


def with_settings(tree, args=None):
    """``tree`` with ``args``' --modes and --physics."""
    import dataclasses

    modes = getattr(args, "modes", None)
    if modes is not None:
        tree.modes = modes
    settings = dict(getattr(args, "physics", None) or ())
    if settings:
        tree = dataclasses.replace(tree, physics=dataclasses.replace(tree.physics, **settings))
    return tree
