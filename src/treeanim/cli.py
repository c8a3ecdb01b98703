"""The ``treeanim`` command line: view | info | render | trace | bench | export.

Every subcommand reports bad input as one line on stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading

from .table1 import PLURAL, ROWS, TABLE1, TABLE1_FPS

#: What plain ``treeanim`` runs.
DEFAULT_COMMAND = ["view"]


class UsageError(Exception):
    """Bad command-line input: printed as one line, exit status 2."""


def _season(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"expected a number in [0, 1], got {text!r}")
    return value


#: Upper bound of times, rates and counts on the command line: large enough for any real use,
#: small enough that products of them stay finite and allocations sane.
LIMIT = 1e6
#: Most frames (or samples) one command may produce.
MAX_FRAMES = 1_000_000
#: Most simulation steps one command may take (hours of work at a few ms a step).
MAX_STEPS = 2_000_000


def _number(kind, lo: float, hi: float, lo_open: bool):
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
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return value

    return parse


def _positive(kind, hi: float = LIMIT):
    return _number(kind, 0, hi, lo_open=True)


_non_negative = _number(float, 0, LIMIT, lo_open=False)


def _checked(parse):
    """An argparse type from a parser that raises ValueError with a clear message."""

    def checked(text: str):
        try:
            return parse(text)
        except ValueError as e:
            raise argparse.ArgumentTypeError(str(e)) from None

    checked.__name__ = parse.__name__
    return checked


def _size(text: str) -> tuple[int, int]:
    from treeanim.offline import parse_size

    return _checked(parse_size)(text)


def _vector(what: str, force: bool = False):
    """An argparse type: X,Y,Z (a force: of at most the simulation's largest pull)."""
    from treeanim.scripted import parse_force, parse_vector

    parse = parse_force if force else parse_vector
    return _checked(lambda text: parse(text, what))


def _pull(text: str):
    from treeanim.scripted import parse_pull

    return _checked(parse_pull)(text)


def _wind_speed(text: str) -> float:
    from treeanim.physics.wind import MAX_SPEED

    return _number(float, 0, MAX_SPEED, lo_open=False)(text)


def add_season_option(p: argparse.ArgumentParser) -> None:
    """--season, --leaves and --modes, for every command that builds a tree."""
    from treeanim.model.qsm import SPECIES

    p.add_argument("--season", type=_season, default=0.0, help="0 = summer … 1 = winter (default 0)")
    p.add_argument("--leaves", default=None, metavar="SPECIES[:PER_METRE]",
                   help=f"a TreeQSM model's leaves along its twigs: none (default) or {', '.join(SPECIES)}, "
                   "optionally with leaves per metre of twig (e.g. cherry:80)")
    p.add_argument("--modes", choices=["paper", "physical"], default=None,
                   help="modal f and zeta: paper (Eqs. 20-22; the presets' default) or physical (beam theory; "
                   "TreeQSM models' default)")


def add_wind_speed_options(p: argparse.ArgumentParser, wind: float = 5.0) -> None:
    """--wind and --wind-preset (the viewer's and the offline commands' wind)."""
    from treeanim.physics.wind import WIND_PRESETS

    names = ", ".join(f"{k} (Beaufort {v['beaufort']}, {v['speed']:g} m/s)" for k, v in WIND_PRESETS.items())
    p.add_argument("--wind", type=_wind_speed, default=None, metavar="SPEED",
                   help=f"mean wind speed at the canopy top, m/s (default {wind:g}, or the preset's; 0 = calm)")
    p.add_argument("--wind-preset", choices=list(WIND_PRESETS), default=None, metavar="NAME",
                   help=f"a named wind: {names}; --wind (and --turbulence where it exists) override its values")


def add_wind_options(p: argparse.ArgumentParser, wind: float = 5.0) -> None:
    """Wind, season and seed options (the scene around the tree)."""
    from treeanim.physics.wind import MODELS

    add_wind_speed_options(p, wind)
    p.add_argument("--wind-model", choices=list(MODELS), default=None,
                   help="physical (default: turbulence in metres carried downwind, gusts, canopy profile) "
                   "or paper (Hu, Chiba & He 2012, Eqs. 13-18; the default with --paper)")
    p.add_argument("--wind-dir", type=_vector("direction"), default=(1.0, 0.0, 0.0), metavar="X,Y,Z",
                   help="wind direction; needs a horizontal part (default 1,0,0)")
    p.add_argument("--turbulence", type=_number(float, 0, 2, lo_open=False), default=None, metavar="T",
                   help="physical: turbulence intensity at the canopy top in [0, 1] (default 0.3); "
                   "paper: lambda of Eq. 17 in [1, 2] (default 1.5)")
    add_season_option(p)
    p.add_argument("--seed", type=_number(int, 0, 2**32 - 1, lo_open=False), default=0,
                   help="seed of the wind and the modal noise (default 0)")
    p.set_defaults(wind_default=wind)


def wind_settings(args) -> dict:
    """WindField keyword arguments from :func:`add_wind_options` (speed 0 means calm: no field)."""
    from treeanim.physics.wind import wind_preset

    model = getattr(args, "wind_model", None)
    kw = dict(model=model or ("paper" if getattr(args, "paper", False) else "physical"))
    if getattr(args, "wind_preset", None):
        if kw["model"] == "paper":
            raise UsageError("--wind-preset: the named winds are for --wind-model physical")
        kw.update(wind_preset(args.wind_preset))
    kw.setdefault("speed", args.wind_default)
    if args.wind is not None:
        kw["speed"] = args.wind
    if getattr(args, "turbulence", None) is not None:
        kw["turbulence"] = args.turbulence
    kw.update(direction=args.wind_dir, seed=args.seed)
    return kw


def add_scene_options(p: argparse.ArgumentParser, seconds: float | None = 5.0, fps: float = 30.0,
                      seconds_help: str | None = None) -> None:
    """Options shared by the offline commands: the preset, timing, wind, season and pulls."""
    p.add_argument("preset", help="preset name (see 'treeanim list') or path to a preset .toml")
    p.add_argument("--seconds", type=_positive(float), default=seconds,
                   help=seconds_help or f"duration in seconds (default {seconds:g})")
    p.add_argument("--fps", type=_positive(float), default=fps, help=f"frames per second (default {fps:g})")
    add_wind_options(p)
    p.add_argument("--pull", type=_pull, action="append", default=[], metavar="OBJECT:FX,FY,FZ@T0-T1",
                   help="pull OBJECT's tip with a world force in newtons from T0 to T1 s, then let go; repeatable")
    p.add_argument("--paper", action="store_true",
                   help="the paper's model: every object on its own, linear drag, the paper's wind field "
                   "(default: the load path in the physical wind)")


def check_frames(seconds: float, fps: float, step_rate: float = 60.0) -> int:
    """The number of frames ``seconds`` at ``fps`` give; UsageError beyond :data:`MAX_FRAMES`,
    or beyond :data:`MAX_STEPS` simulation steps (one a frame, and at least ``step_rate`` a
    second: scripted frames step at most 1/60 s at a time)."""
    n = seconds * fps
    if n > MAX_FRAMES:
        raise UsageError(f"--seconds {seconds:g} at --fps {fps:g} is {n:.3g} frames; at most {MAX_FRAMES:,}")
    steps = seconds * max(fps, step_rate)
    if steps > MAX_STEPS:
        raise UsageError(f"--seconds {seconds:g} takes {steps:.3g} simulation steps; at most {MAX_STEPS:,} "
                         f"(about {MAX_STEPS / 3600 / 60:.0f} hours of simulated time at 60 steps a second)")
    return int(round(n))


def make_simulation(args):
    """The tree and a Simulation set up from :func:`add_scene_options`."""
    import treeanim as ta
    from treeanim.scripted import check_pulls

    tree = load_any(args.preset, args)
    try:
        check_pulls(args.pull, tree.n_objects)
        wind = None
        kw = wind_settings(args)
        if kw["speed"] > 0:
            wind = ta.WindField(**kw)
        sim = ta.Simulation(tree, wind=wind, season=args.season, seed=args.seed,
                            load_path=not getattr(args, "paper", False))
    except ValueError as e:
        raise UsageError(str(e)) from None
    return tree, sim


def output_path(text: str, suffixes: tuple[str, ...], option: str = "--out"):
    """Check an output path: a known extension and a folder where files can really be created."""
    from pathlib import Path

    from treeanim import offline

    path = Path(text)
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"{option} {text}: unknown extension {path.suffix or '(none)'!r}; expected {', '.join(suffixes)}")
    try:
        offline.check_file(path, text)
    except offline.InputError as e:
        raise UsageError(str(e).replace("--out ", f"{option} ", 1)) from None
    return path


def cmd_export(args) -> int:
    """Bake the simulated motion into a glTF 2.0 file."""
    import numpy as np
    from tqdm import tqdm

    from treeanim import export, scripted

    out = output_path(args.out, (".glb", ".gltf"))
    tree, sim = make_simulation(args)
    skel = export.skeleton(tree)
    n = check_frames(args.seconds, args.fps)
    fade = check_frames(args.loop, args.fps)
    if n < 2:
        raise UsageError(f"--seconds {args.seconds:g} at --fps {args.fps:g} gives fewer than 2 frames")
    if fade >= n:
        raise UsageError(f"--loop {args.loop:g}: the cross-fade must be shorter than --seconds")
    size = (n + fade) * skel.count * 16
    if size > 8e9:
        raise UsageError(f"{n + fade:,} frames of {skel.count:,} joints would need {size / 1e9:.0f} GB of keys; "
                         "export fewer seconds or frames per second")
    keys = np.empty((n + fade, skel.count, 4), np.float32)
    bar = tqdm(total=n + fade, desc=f"baking {tree.name}", unit="frame", disable=args.quiet, leave=False)
    for k in scripted.frames(sim, (n + fade) / args.fps, args.fps, args.pull):
        keys[k] = export.local_rotations(skel, sim.rotations)
        bar.update()
    bar.close()
    doc, data = export.build_gltf(tree, export.crossfade_loop(keys, fade), args.fps, season=args.season,
                                  present=sim.present)
    files = export.write_gltf(out, doc, data)
    size = sum(f.stat().st_size for f in files)
    print(f"wrote {', '.join(map(str, files))}: {skel.count} joints, {n} frames at {args.fps:g} fps "
          f"({n / args.fps:.2f} s), {size / 1e6:.1f} MB")
    return 0


# ---------------------------------------------------------------------------- render | trace | bench
def _one_line_errors(p: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Report ``p``'s bad options as one line on stderr, exit status 2 (no usage dump)."""

    def error(message: str):
        print(f"{p.prog}: error: {message} (see '{p.prog} --help')", file=sys.stderr)
        sys.exit(2)

    p.error = error
    return p


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if value != value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


#: MSAA sample counts a GL implementation may offer (more are clamped to what it has).
SAMPLES = (0, 1, 2, 4, 8, 16)


def _samples(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value not in SAMPLES:
        raise argparse.ArgumentTypeError(f"expected one of {', '.join(map(str, SAMPLES))}, got {text!r}")
    return value


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB" if n >= 1e5 else f"{n / 1e3:.0f} kB"


def cmd_render(args) -> int:
    """Render an MP4 / GIF, a folder of PNG frames, or one PNG still, offscreen."""
    from treeanim import offline

    try:
        target = offline.render_target(args.out)
    except offline.InputError as e:
        raise UsageError(str(e)) from None
    seconds = args.seconds if args.seconds is not None else (
        offline.STILL_SECONDS if target.kind == "still" else 5.0)
    w, h = args.size
    job = offline.RenderJob(target, w, h, args.fps, seconds, start=args.start, season=args.season, pulls=args.pull,
                            azimuth=args.azimuth, elevation=args.elevation, distance=args.distance,
                            samples=args.samples, quiet=args.quiet)
    check_frames(args.start + seconds, args.fps)
    if target.kind != "still" and job.frame_range()[1] < 1:
        raise UsageError(f"--seconds {seconds:g} at --fps {args.fps:g} gives no frame")
    tree, sim = make_simulation(args)
    try:
        res = offline.run_render(job, tree, sim, log=lambda m: print(m, file=sys.stderr))
    except offline.GLUnavailable as e:
        print(f"treeanim: error: {e}", file=sys.stderr)
        return 1
    if target.kind == "still":
        print(f"wrote {res.path}: {w}×{h}, {tree.name} after {job.start + seconds:g} s, {_mb(res.bytes)}")
        return 0
    what = f"{res.frames} frame{'s' * (res.frames != 1)}"
    dur = f"{res.frames / args.fps:.2f} s at {args.fps:g} fps"
    if target.kind == "video":
        pad = f", padded to {res.size[0]}×{res.size[1]}" if res.size != (w, h) else ""
        where = f"{res.path} ({w}×{h}{pad}, {dur}, {_mb(res.bytes)})"
    else:
        last = offline.FRAME_NAME.format(max(res.frames - 1, 0))
        where = f"{res.path}/: {offline.FRAME_NAME.format(0)} … {last} ({w}×{h}, {dur}, {_mb(res.bytes)})"
    if res.interrupted:
        if res.kept:
            print(f"interrupted: kept {what} of {res.total} in {where}", file=sys.stderr)
        else:
            print("interrupted before the first frame: nothing written", file=sys.stderr)
        return 130
    print(f"wrote {what} to {where}")
    return 0


def cmd_trace(args) -> int:
    """Pull one object's tip, let go, and record the tip's free swing as CSV (and a plot)."""
    import numpy as np

    from treeanim import offline

    out = output_path(args.out, (".csv",))
    plot = output_path(args.plot, (".png", ".svg", ".pdf"), "--plot") if args.plot else None
    if plot is not None:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise UsageError(f"--plot {offline.PLOTS_HINT}") from None
    scene = argparse.Namespace(**vars(args))
    scene.pull = []
    tree, sim = make_simulation(scene)
    if not 0 <= args.object < tree.n_objects:
        raise UsageError(f"--object {args.object}: the tree has objects 0 to {tree.n_objects - 1}")
    check_frames(args.hold + args.seconds, args.rate, step_rate=0.0)  # a trace steps once a sample
    try:
        tr = offline.run_trace(sim, args.object, args.pull, args.hold, args.seconds, args.rate)
    except offline.InputError as e:
        raise UsageError(str(e)) from None
    offline.write_trace_csv(out, tr)
    if plot is not None:
        offline.plot_trace(plot, tr, title=f"{tree.name}: pull {','.join(f'{v:g}' for v in args.pull)} N, "
                                           f"released after {args.hold:g} s")
    d = tr.tips - tr.rest
    f, z = tr.f, tr.zeta
    fx = offline.zero_crossing_frequency(tr.times, d[:, 0] - d[-len(d) // 4:, 0].mean())
    fz = offline.zero_crossing_frequency(tr.times, d[:, 2] - d[-len(d) // 4:, 2].mean())
    print(f"wrote {out}: {len(tr.times)} samples of object {args.object} ({tr.kind})'s tip over {args.seconds:g} s "
          f"after release at {args.rate:g} Hz" + (f"; plot {plot}" if plot else ""))
    crossing = ", ".join(f"{axis} {hz:.3f} Hz" if np.isfinite(hz) else f"{axis} too few to tell"
                         for axis, hz in (("x", fx), ("z", fz)))
    print(f"held deflection {np.linalg.norm(tr.held - tr.rest) * 100:.1f} cm; modes f u,v,w = "
          f"{f[0]:.3f}, {f[1]:.3f}, {f[2]:.3f} Hz, ζ = {z[0]:.3f}, {z[1]:.3f}, {z[2]:.3f}; "
          f"zero crossings: {crossing}")
    return 0


def cmd_bench(args) -> int:
    """The paper's Table 1 beside ours, measured on this machine."""
    import json

    import treeanim as ta
    from treeanim import offline

    keys = args.presets or list(ROWS)
    known = list(ROWS) + [p for p in ta.list_presets() if p not in ROWS]
    for k in keys:
        if k not in known:
            raise UsageError(f"--presets {k}: unknown; expected some of {', '.join(known)}")
    out = output_path(args.json, (".json",), "--json") if args.json else None
    w, h = args.size
    try:
        res = offline.run_bench(keys, w, h, frames=args.frames, steps=args.steps, samples=args.samples,
                                wind=args.wind, quiet=args.quiet)
    except offline.GLUnavailable as e:
        print(f"treeanim: error: {e}", file=sys.stderr)
        return 1
    print(offline.format_bench(res))
    if out is not None:
        offline.write_text(out, json.dumps(res, indent=2) + "\n")
        print(f"wrote {out}")
    return 0


# ---------------------------------------------------------------------------- view
def cmd_view(args) -> int:
    """Open the interactive viewer (the default command)."""
    from treeanim.app.main import ViewerUnavailable, view

    tree = load_any(args.preset, args)
    try:
        view(tree, season=args.season, wind_speed=args.wind, wind_preset=args.wind_preset, size=args.size,
             frames=args.frames,
             samples=args.samples)
    except (ViewerUnavailable, ValueError) as e:
        raise UsageError(str(e)) from None
    return 0


def load_any(name_or_path: str, args=None):
    """A preset by name, a preset TOML file or a TreeQSM model (.txt, .csv, .mat) by path, with
    ``args``' --leaves (QSM only) and --modes."""
    import treeanim as ta
    from treeanim.model.qsm import QSM_SUFFIXES, load_file

    leaves, modes = getattr(args, "leaves", None), getattr(args, "modes", None)
    if name_or_path.lower().endswith((*QSM_SUFFIXES, ".toml")):
        tree = load_file(name_or_path, leaves=leaves)
    elif leaves is not None:
        raise UsageError("--leaves is for TreeQSM models (.txt, .csv, .mat); a preset has its own leaves")
    else:
        tree = ta.load_preset(name_or_path)
    if modes is not None:
        tree.modes = modes
    return tree


def cmd_info(args) -> int:
    """Print a preset's statistics beside the paper's Table 1 row."""
    import treeanim as ta
    from treeanim.model.params import ModeRange

    tree = load_any(args.preset, args)
    stats = tree.stats(args.season)
    key = tree.name + ("@winter" if args.season >= 1.0 and tree.name == "large_cherry" else "")
    paper = {row[0]: row for row in TABLE1.get(key, [])}
    params = tree.physics
    modal = ta.Simulation(tree, season=args.season).modes if tree.modes == "physical" else None
    print(f"{tree.name} (season {args.season:g}, seed {tree.seed}) — {tree.source}")
    print(f"{'object type':<12}{'objects':>16}{'nodes':>18}{'triangles':>22}   f range      ζ range")
    print(f"{'':<12}{'ours / paper':>16}{'ours / paper':>18}{'ours / paper':>22}")
    for kind in ("branch", "leaf", "blade"):
        n = stats[PLURAL[kind]]
        if n == 0 and kind not in paper:
            continue
        p = paper.get(kind)
        ref = (lambda i: f"{p[i]:,}") if p else (lambda i: "—")
        modes = params.modes(kind, args.season)
        if modal is not None and kind == "branch":  # beam theory: the range it gives
            f, z = modal.f[tree.kind == kind, 0], modal.zeta[tree.kind == kind, 0]
            modes = ModeRange((f.min(), f.max()), (z.min(), z.max()))
        mr = f"{modes.f[0]:.2f}–{modes.f[1]:.2f}  {modes.zeta[0]:.2f}–{modes.zeta[1]:.2f}" if modes else ""
        print(
            f"{kind:<12}{n:>7,} / {ref(1):>6}{stats[kind + '_nodes']:>8,} / {ref(2):>7}"
            f"{stats[kind + '_triangles']:>11,} / {ref(3):>8}   {mr}"
        )
    total_p = [f"{sum(r[i] for r in paper.values()):,}" if paper else "—" for i in (2, 3)]  # no paper row: —
    print(f"{'total':<12}{stats['objects']:>7,}{'':>9}{stats['nodes']:>8,} / {total_p[0]:>7}"
          f"{stats['triangles']:>11,} / {total_p[1]:>8}")
    if modal is not None:
        print(f"modes: physical (beam theory); the trunk sways at {modal.f[0, 0]:.3f} Hz, "
              f"ζ {modal.zeta[0, 0]:.3f}")
    if key in TABLE1_FPS:
        print(f"paper's frame rate: {TABLE1_FPS[key]} FPS (2012, Core2 Duo 2.8 GHz, GeForce 9500 GT)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    parser = argparse.ArgumentParser(
        prog="treeanim",
        description="Interactive trees in wind and under the mouse (Hu, Chiba & He 2012). "
        "With no command, opens the viewer on the small cherry.",
    )
    from treeanim import __version__

    parser.add_argument("--version", action="version", version=f"treeanim {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("info", help="print a preset's statistics beside the paper's Table 1",
                       description="Print a preset's objects, nodes and triangles beside the paper's Table 1 row.")
    p.add_argument("preset", help="preset name (see 'treeanim list') or path to a preset .toml")
    add_season_option(p)
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("export", help="bake the animation into a glTF 2.0 file (.glb or .gltf)",
                       description="Simulate and bake the motion into a glTF 2.0 file: the mesh, a skin with one "
                       "joint per segment and rotation keys at --fps. Opens in Blender, three.js and game engines.")
    add_scene_options(p)
    p.add_argument("--out", required=True, help="output file: tree.glb, or tree.gltf (+ tree.bin)")
    p.add_argument("--loop", type=_non_negative, default=0.0, metavar="SECONDS",
                   help="make the clip loop by cross-fading this many seconds of its end into its start (default 0)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_export)

    p = sub.add_parser(
        "render", help="render a video (.mp4, .gif), PNG frames (a folder) or one PNG still, offscreen",
        description="Simulate and render offscreen (EGL): a video (.mp4 H.264, or .gif), a folder of PNG frames "
        "(frame_00000.png, ...), or one .png still of the state after --seconds. Ctrl-C stops after the current "
        "frame and keeps a playable file of what was rendered.")
    add_scene_options(p, seconds=None,  # a still's default differs from a clip's
                      seconds_help="clip length in seconds (default 5); for a .png, the time simulated before "
                      "the still (default 2)")
    p.add_argument("--out", required=True,
                   help="clip.mp4 | clip.gif | frames/ (a folder of PNG frames) | still.png")
    p.add_argument("--size", type=_size, default=(1280, 720), metavar="WxH", help="image size (default 1280x720)")
    p.add_argument("--start", type=_non_negative, default=0.0, metavar="SECONDS",
                   help="simulated time of the first frame; the tree starts from rest at 0 (default 0)")
    p.add_argument("--azimuth", type=_finite, default=0.0, metavar="DEG",
                   help="camera direction about the vertical; 0 looks along -z, the default wind blows left "
                   "to right (default 0)")
    p.add_argument("--elevation", type=_finite, default=None, metavar="DEG",
                   help="camera height angle above the horizon (default 2, or 25 for flat scenes like grass)")
    p.add_argument("--distance", type=_positive(float), default=None, metavar="METRES",
                   help="camera distance to the tree's centre (default: framed on the tree)")
    p.add_argument("--samples", type=_samples, default=4, help="MSAA samples (default 4; 0 = none)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser(
        "trace", help="pull one object's tip, let go, and record its trace (CSV, optional plot)",
        description="Pull object OBJECT's tip with a constant world force until it sits at its static "
        "deflection, let go, and record the tip's position (t, x, y, z) for --seconds at --rate samples per "
        "second: the Lissajous / harmonograph trace of the paper's Figs. 1 and 4.")
    p.add_argument("preset", help="preset name (see 'treeanim list') or path to a preset .toml")
    p.add_argument("--object", type=int, default=0, metavar="I", help="object index (default 0, e.g. the beam)")
    p.add_argument("--pull", type=_vector("force", force=True), required=True, metavar="FX,FY,FZ",
                   help="world force on the tip in newtons, e.g. 1.5,0,1.2 for the beam")
    p.add_argument("--hold", type=_positive(float), default=2.0, metavar="SECONDS",
                   help="how long the pull is held before release (default 2)")
    p.add_argument("--seconds", type=_positive(float), default=10.0, help="seconds recorded after release (default 10)")
    p.add_argument("--rate", type=_positive(float), default=240.0, metavar="HZ",
                   help="samples (and simulation steps) per second (default 240)")
    p.add_argument("--out", required=True, help="trace.csv (columns t,x,y,z; t = 0 at release)")
    p.add_argument("--plot", default=None, metavar="FILE",
                   help="also plot the horizontal (x-z) trace: .png, .svg or .pdf (needs matplotlib)")
    add_wind_options(p, wind=0.0)  # calm by default: a free swing
    p.set_defaults(func=cmd_trace)

    p = sub.add_parser(
        "bench", help="measure the paper's Table 1 on this machine (simulation and render times, FPS)",
        description="For every preset: objects, nodes and triangles beside the paper's Table 1, the median "
        "simulation time per step (wind on), the median offscreen render time per frame (pixels read back), "
        "and the frame rate they allow, with this machine's CPU and GL renderer.")
    p.add_argument("--presets", nargs="+", metavar="NAME",
                   help="rows to measure (default: small_cherry large_cherry large_cherry@winter tulip_poplar "
                   "grassland)")
    p.add_argument("--size", type=_size, default=(1280, 720), metavar="WxH", help="render size (default 1280x720)")
    p.add_argument("--frames", type=_positive(int), default=20, help="frames rendered per preset (default 20)")
    p.add_argument("--steps", type=_positive(int), default=200, help="simulation steps per preset (default 200)")
    p.add_argument("--samples", type=_samples, default=4, help="MSAA samples (default 4)")
    p.add_argument("--wind", type=_wind_speed, default=5.0, metavar="SPEED", help="wind speed, m/s (default 5)")
    p.add_argument("--json", default=None, metavar="FILE", help="also write every figure to this .json file")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser(
        "view", help="open the interactive viewer (what plain 'treeanim' does)",
        description="Open the viewer: the tree in wind; drag a branch or leaf to pull it and let go to watch it "
        "swing; sliders for wind, season and physics. Needs a display and OpenGL 3.3.")
    p.add_argument("preset", nargs="?", default="small_cherry",
                   help="preset name (see 'treeanim list') or path to a preset .toml (default small_cherry)")
    add_season_option(p)
    add_wind_speed_options(p)
    p.add_argument("--size", type=_size, default=(1280, 720), metavar="WxH",
                   help="window size (default 1280x720)")
    p.add_argument("--samples", type=_samples, default=None, metavar="N",
                   help="MSAA samples: 0, 1, 2, 4, 8 or 16 (default 4, or 0 on a software renderer such as "
                        "llvmpipe)")
    p.add_argument("--frames", type=_positive(int), default=None, metavar="N",
                   help="quit after N frames (for scripted runs)")
    p.set_defaults(func=cmd_view)

    p = sub.add_parser("list", help="list the shipped presets", description="List the shipped presets.")
    p.set_defaults(func=lambda args: print("\n".join(__import__("treeanim").list_presets())) or 0)
    for p in (parser, *sub.choices.values()):
        _one_line_errors(p)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``treeanim`` console script."""
    from treeanim.model.errors import PresetError

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminated)  # `kill`: unwind, so temporary files are removed
    try:  # building the parser imports the wind's presets: Ctrl-C may come that early
        parser = build_parser()
        args = parser.parse_args(argv)
        if args.command is None:
            args = parser.parse_args(DEFAULT_COMMAND)
        code = int(args.func(args) or 0)
        sys.stdout.flush()
        return code
    except BrokenPipeError:  # the reader went away (`treeanim info | head`): stop quietly
        _stdout_to_devnull()
        return 141
    except (PresetError, UsageError) as e:
        print(f"treeanim: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # a write that failed (disk full, name too long ...): the old file is kept
        if e.filename is None:  # standard output itself (`treeanim list > /dev/full`)
            _stdout_to_devnull()
        where = f"{e.filename}: " if e.filename is not None else ""
        print(f"treeanim: error: {where}{e.strerror or e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("treeanim: interrupted", file=sys.stderr)
        return 130


def _terminated(signum, frame) -> None:
    """SIGTERM: leave through the normal unwinding (cleanups run), exit status 143."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a second one ends at once
    raise SystemExit(128 + signal.SIGTERM)


def _stdout_to_devnull() -> None:
    """Point standard output at /dev/null, so that the interpreter's last flush of what is
    left in its buffer cannot fail again on the way out."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # no file descriptor behind stdout
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
