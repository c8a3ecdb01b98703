"""The ``treeanim`` command line: view | info | render | trace | bench | export.

Every subcommand reports bad input as one line on stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading

from . import options as opt
from .errors import GLUnavailable, InputError, UsageError
from .offline.export import cmd_export
from .options import load_any, make_simulation, output_path
from .table1 import ROWS, TABLE1, TABLE1_FPS

#: What plain ``treeanim`` runs.
DEFAULT_COMMAND = ["view"]


# ---------------------------------------------------------------------------- render | trace | bench
def _one_line_errors(p: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Report ``p``'s bad options as one line on stderr, exit status 2 (no usage dump)."""

    def error(message: str):
        print(f"{p.prog}: error: {message} (see '{p.prog} --help')", file=sys.stderr)
        sys.exit(2)

    p.error = error
    return p


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB" if n >= 1e5 else f"{n / 1e3:.0f} kB"


def cmd_render(args) -> int:
    """Render an MP4 / GIF, a folder of PNG frames, or one PNG still, offscreen."""
    from treeanim.offline import render
    from treeanim.offline.sinks import FRAME_NAME
    from treeanim.offline.target import render_target

    target = render_target(args.out)
    seconds = args.seconds if args.seconds is not None else (
        render.STILL_SECONDS if target.kind == "still" else 5.0)
    w, h = args.size
    job = render.RenderJob(target, w, h, args.fps, seconds, start=args.start, season=args.season,
                           pulls=opt.scheduled(args),
                           azimuth=args.azimuth, elevation=args.elevation, distance=args.distance,
                           samples=args.samples, quiet=args.quiet)
    opt.check_frames(args.start + seconds, args.fps)
    if target.kind != "still" and job.frame_range()[1] < 1:
        raise UsageError(f"--seconds {seconds:g} at --fps {args.fps:g} gives no frame")
    tree, sim = make_simulation(args)
    try:
        res = render.run_render(job, tree, sim, log=lambda m: print(m, file=sys.stderr))
    except GLUnavailable as e:
        print(one_line(f"treeanim: error: {e}"), file=sys.stderr)
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
        last = FRAME_NAME.format(max(res.frames - 1, 0))
        where = f"{res.path}/: {FRAME_NAME.format(0)} … {last} ({w}×{h}, {dur}, {_mb(res.bytes)})"
    if res.interrupted:
        if res.kept:
            print(f"interrupted: kept {what} of {res.total} in {where}", file=sys.stderr)
        else:
            print("interrupted before the first frame: nothing written", file=sys.stderr)
        return 130
    print(f"wrote {what} to {where}")
    return 0


def cmd_trace(args) -> int:
    """Pull (or drag) one object's tip, let go, and record the tip's free swing as CSV (and a plot)."""
    import numpy as np

    from treeanim.offline import trace

    out = output_path(args.out, (".csv",))
    plot = output_path(args.plot, (".png", ".svg", ".pdf"), "--plot") if args.plot else None
    if plot is not None:
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            raise UsageError(f"--plot {trace.PLOTS_HINT}") from None
    if args.drag is not None and args.paper:
        raise UsageError("--drag needs the tree model, not --paper (the paper's objects are independent: use --pull)")
    scene = argparse.Namespace(**vars(args))
    scene.pull, scene.drag = [], []
    tree, sim = make_simulation(scene)
    if not 0 <= args.object < tree.n_objects:
        raise UsageError(f"--object {args.object}: the tree has objects 0 to {tree.n_objects - 1}")
    opt.check_frames(args.hold + args.seconds, args.rate)
    tr = trace.run_trace(sim, args.object, args.pull, args.hold, args.seconds, args.rate, drag=args.drag)
    trace.write_trace_csv(out, tr)
    if plot is not None:
        held = (f"pull {','.join(f'{v:g}' for v in args.pull)} N" if args.drag is None
                else f"drag to {','.join(f'{v:g}' for v in args.drag)} m")
        trace.plot_trace(plot, tr, title=f"{tree.name}: {held}, released after {args.hold:g} s")
    d = tr.tips - tr.rest
    fx = trace.zero_crossing_frequency(tr.times, d[:, 0] - d[-len(d) // 4:, 0].mean())
    fz = trace.zero_crossing_frequency(tr.times, d[:, 2] - d[-len(d) // 4:, 2].mean())
    print(f"wrote {out}: {len(tr.times)} samples of object {args.object} ({tr.kind})'s tip over {args.seconds:g} s "
          f"after release at {args.rate:g} Hz" + (f"; plot {plot}" if plot else ""))
    crossing = ", ".join(f"{axis} {hz:.3f} Hz" if np.isfinite(hz) else f"{axis} too few to tell"
                         for axis, hz in (("x", fx), ("z", fz)))
    modes = ""
    if tr.f is not None:  # the paper's model: the object's own modes
        f, z = tr.f, tr.zeta
        modes = f"modes f u,v,w = {f[0]:.3f}, {f[1]:.3f}, {f[2]:.3f} Hz, ζ = {z[0]:.3f}, {z[1]:.3f}, {z[2]:.3f}; "
    print(f"held deflection {np.linalg.norm(tr.held - tr.rest) * 100:.1f} cm; {modes}zero crossings: {crossing}")
    return 0


def cmd_bench(args) -> int:
    """The paper's Table 1 beside ours, measured on this machine."""
    import json

    import treeanim as ta
    from treeanim.files import write_text
    from treeanim.offline import bench

    keys = args.presets or list(ROWS)
    known = list(ROWS) + [p for p in ta.list_presets() + ta.list_scenes() if p not in ROWS]
    for k in keys:
        if k not in known:
            raise UsageError(f"--presets {k}: unknown; expected some of {', '.join(known)}")
    out = output_path(args.json, (".json",), "--json") if args.json else None
    w, h = args.size
    try:  # each row is printed as it finishes; Ctrl-C keeps the finished ones, in the JSON too
        res = bench.run_bench(keys, w, h, frames=args.frames, steps=args.steps, samples=args.samples,
                              wind=args.wind, quiet=args.quiet, emit=lambda text: print(text, flush=True))
    except GLUnavailable as e:
        print(one_line(f"treeanim: error: {e}"), file=sys.stderr)
        return 1
    if out is not None and res["rows"]:
        write_text(out, json.dumps(res, indent=2) + "\n")
        print(f"wrote {out}" + (f" ({len(res['rows'])} of {len(keys)} rows)" if res["interrupted"] else ""))
    if res["interrupted"]:
        done = len(res["rows"])
        print(f"interrupted: {done} of {len(keys)} row{'s' * (len(keys) != 1)} measured"
              + ("" if done or out is None else f"; nothing written to {out}"), file=sys.stderr)
        return 130
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


def cmd_list(args) -> int:
    """The shipped presets and scenes, a line each: name, size and description."""
    from treeanim.describe import preset_lines, scene_list_lines

    print("\n".join(preset_lines() + scene_list_lines()))
    return 0


def cmd_info(args) -> int:
    """Print a preset's statistics beside the paper's Table 1 row (or, --objects, its objects)."""
    import treeanim as ta
    from treeanim.model.params import ModeRange
    from treeanim.model.scene import Scene
    from treeanim.model.tree import PLURAL

    tree = load_any(args.preset, args)
    if args.objects:
        from treeanim.describe import object_lines

        print("\n".join(object_lines(tree)))
        return 0
    if isinstance(tree, Scene):
        from treeanim.describe import scene_lines

        print("\n".join(scene_lines(tree, args.season)))
        return 0
    stats = tree.stats(args.season)
    key = tree.name + ("@winter" if args.season >= 1.0 and tree.name == "large_cherry" else "")
    paper = {row[0]: row for row in TABLE1.get(key, [])}
    params = tree.physics
    modal = ta.Simulation(tree, season=args.season, model="paper").modes if tree.modes == "physical" else None
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
    print(f"objects are numbered 0 to {tree.n_objects - 1}, root first, for --pull OBJECT:... and --drag "
          "OBJECT...; --objects lists them")
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

    p = sub.add_parser("info", help="print a tree's statistics beside the paper's Table 1 (or list its objects)",
                       description="Print a tree's objects, nodes and triangles beside the paper's Table 1 row: a "
                       "shipped preset, a preset .toml file, or a TreeQSM cylinder model (a .txt or .csv table, or "
                       "a .mat file, as TreeQSM saves it; --leaves adds leaves along its twigs). --objects lists "
                       "every object by the number that --pull, --drag and trace --object take.")
    p.add_argument("preset", help=opt.PRESET_HELP)
    opt.add_season_option(p)
    p.add_argument("--objects", action="store_true",
                   help="list every object instead: its number, kind, level, parent, nodes, length, base diameter "
                   "and tip")
    p.set_defaults(func=cmd_info)

    p = sub.add_parser("export", help="bake the animation into a glTF 2.0 (.glb, .gltf) or USD file",
                       description="Simulate and bake the motion into a glTF 2.0 or a USD (UsdSkel) file: the mesh, a "
                       "skin with one joint per segment and rotation keys at --fps. Opens in Blender, three.js, game "
                       "engines and USD tools.")
    opt.add_scene_options(p)
    p.add_argument("--out", required=True, help="output file: tree.glb, tree.gltf (+ tree.bin), or tree.usda (text), tree.usdc or "
                   "tree.usd (binary; needs usd-core)")
    p.add_argument("--motion", choices=("keys", "shader"), default="keys",
                   help="keys (default): the simulated motion as rotation keys on a skeleton; shader: a static mesh "
                   "whose vertices carry their branches' pivots, axes and measured frequency, damping and compliance, "
                   "for the reference shader wind (shaders/engine_wind.glsl; .glb or .gltf)")
    p.add_argument("--instances", type=opt.positive(int, 1000), default=None, metavar="K",
                   help="with --motion shader, write a scene as instances (EXT_mesh_gpu_instancing) of K template "
                   "trees per tree source (preset or file), each measured once; a tree takes the template of its "
                   "seed (default: every tree its own mesh)")
    p.add_argument("--loop", type=opt.non_negative, default=0.0, metavar="SECONDS",
                   help="make the clip loop: the simulation runs this many seconds past the end and cross-fades into the "
                   "clip's start; the last key repeats the first (default 0: no loop)")
    budgets = p.add_mutually_exclusive_group()
    budgets.add_argument("--joints", type=opt.checked(opt.joint_budget), default=None, metavar="N",
                         help="merge the skeleton into at most N joints (a whole number >= 2, the root joint "
                         "included) where it costs least motion: petioles ride their leaf, leaves their twig, short "
                         "twigs their branch; reports the error against the full motion (default: all, one joint "
                         "per segment)")
    budgets.add_argument("--target", choices=sorted(opt.JOINT_TARGETS), default=None,
                         help="the joint budget of an engine: " + ", ".join(
                             f"{k} {v}" for k, v in sorted(opt.JOINT_TARGETS.items()))
                         + " (Unreal's default of 256 bones per section; Unity and Godot stay responsive; "
                         "three.js with its bone texture)")
    opt.add_precision_option(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_export)

    p = sub.add_parser(
        "render", help="render a video (.mp4, .gif), PNG frames (a folder) or one PNG still, offscreen",
        description="Simulate and render offscreen (EGL): a video (.mp4 H.264, or .gif), a folder of PNG frames "
        "(frame_00000.png, ...), or one .png still of the state after --seconds. Ctrl-C stops after the current "
        "frame and keeps a playable file of what was rendered.")
    opt.add_scene_options(p, seconds=None,  # a still's default differs from a clip's
                      seconds_help="clip length in seconds (default 5); for a .png, the time simulated before "
                      "the still (default 2)")
    p.add_argument("--out", required=True,
                   help="clip.mp4 | clip.gif | frames/ (a folder of PNG frames) | still.png")
    p.add_argument("--size", type=opt.size, default=(1280, 720), metavar="WxH", help="image size (default 1280x720)")
    p.add_argument("--start", type=opt.non_negative, default=0.0, metavar="SECONDS",
                   help="simulated time of the first frame; the tree starts from rest at 0 (default 0)")
    p.add_argument("--azimuth", type=opt.finite, default=0.0, metavar="DEG",
                   help="camera direction about the vertical; 0 looks along -z, the default wind blows left "
                   "to right (default 0)")
    p.add_argument("--elevation", type=opt.finite, default=None, metavar="DEG",
                   help="camera height angle above the horizon (default 8, or 25 for flat scenes like grass)")
    p.add_argument("--distance", type=opt.number(float, 0.01, 1e5, lo_open=False), default=None, metavar="METRES",
                   help="camera distance to the tree's centre (default: framed on the tree)")
    p.add_argument("--samples", type=opt.samples, default=4, help="MSAA samples (default 4; 0 = none)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser(
        "trace", help="pull (or drag) one object's tip, let go, and record its trace (CSV, optional plot)",
        description="Pull object OBJECT's tip with a constant world force (or drag it toward a world point, "
        "the tree model only) until it sits at its static deflection, let go, and record the tip's position "
        "(t, x, y, z) for --seconds at --rate samples per second: the Lissajous / harmonograph trace of the "
        "paper's Figs. 1 and 4.")
    p.add_argument("preset", help=opt.PRESET_HELP)
    p.add_argument("--object", type=int, default=0, metavar="I",
                   help="the object pulled (default 0: the trunk, or the beam); "
                   + opt.OBJECT_HELP.replace("OBJECT is", "I is"))
    held = p.add_mutually_exclusive_group(required=True)
    held.add_argument("--pull", type=opt.vector("force", force=True), metavar="FX,FY,FZ",
                      help="world force on the tip in newtons, e.g. 1.5,0,1.2 for the beam")
    held.add_argument("--drag", type=opt.vector("target"), metavar="X,Y,Z",
                      help="drag the tip toward this world point (m) instead (the tree model only)")
    p.add_argument("--hold", type=opt.positive(float), default=2.0, metavar="SECONDS",
                   help="how long the pull is held before release (default 2)")
    p.add_argument("--seconds", type=opt.positive(float), default=10.0, help="seconds recorded after release (default 10)")
    p.add_argument("--rate", type=opt.positive(float), default=240.0, metavar="HZ",
                   help="samples (and simulation steps) per second (default 240)")
    p.add_argument("--out", required=True, help="trace.csv (columns t,x,y,z; t = 0 at release)")
    p.add_argument("--plot", default=None, metavar="FILE",
                   help="also plot the horizontal (x-z) trace: .png, .svg or .pdf (needs matplotlib)")
    opt.add_wind_options(p, wind=0.0)  # calm by default: a free swing
    opt.add_model_option(p)
    p.set_defaults(func=cmd_trace)

    p = sub.add_parser(
        "bench", help="measure the paper's Table 1 on this machine (simulation and render times, FPS)",
        description="For every preset: objects, nodes and triangles beside the paper's Table 1, the median "
        "simulation time per step (wind on), the median offscreen render time per frame (pixels read back), "
        "and the frame rate they allow, with this machine's CPU and GL renderer.")
    p.add_argument("--presets", nargs="+", metavar="NAME",
                   help="rows to measure: presets or scenes (default: small_cherry large_cherry "
                   "large_cherry@winter tulip_poplar grassland)")
    p.add_argument("--size", type=opt.size, default=(1280, 720), metavar="WxH", help="render size (default 1280x720)")
    p.add_argument("--frames", type=opt.positive(int), default=20, help="frames rendered per preset (default 20)")
    p.add_argument("--steps", type=opt.positive(int), default=200,
                   help="simulated 1/60 s frames timed per preset (default 200)")
    p.add_argument("--samples", type=opt.samples, default=4, help="MSAA samples (default 4)")
    p.add_argument("--wind", type=opt.wind_speed, default=5.0, metavar="SPEED", help="wind speed, m/s (default 5)")
    p.add_argument("--json", default=None, metavar="FILE", help="also write every figure to this .json file")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_bench)

    p = sub.add_parser(
        "view", help="open the interactive viewer (what plain 'treeanim' does)",
        description="Open the viewer: the tree in wind; drag a branch or leaf to pull it and let go to watch it "
        "swing; sliders for wind, season and physics. Needs a display and OpenGL 3.3.")
    p.add_argument("preset", nargs="?", default="small_cherry", help=opt.PRESET_HELP + " (default small_cherry)")
    opt.add_season_option(p)
    opt.add_wind_speed_options(p)
    p.add_argument("--size", type=opt.size, default=(1280, 720), metavar="WxH",
                   help="window size (default 1280x720)")
    p.add_argument("--samples", type=opt.samples, default=None, metavar="N",
                   help="MSAA samples: 0, 1, 2, 4, 8 or 16 (default 4, or 0 on a software renderer such as "
                        "llvmpipe)")
    p.add_argument("--frames", type=opt.positive(int), default=None, metavar="N",
                   help="quit after N frames (for scripted runs)")
    p.set_defaults(func=cmd_view)
    _help_ends_with(p, lambda: __import__("treeanim.describe").describe.viewer_controls())

    p = sub.add_parser("list", help="list the shipped presets and scenes: size and description",
                       description="List the shipped presets, a line each: name, height, objects and triangles "
                       "(in summer) and what it is; then the shipped scenes: their trees and what they are.")
    p.set_defaults(func=cmd_list)
    for p in (parser, *sub.choices.values()):
        _one_line_errors(p)
    return parser


def _help_ends_with(p: argparse.ArgumentParser, make) -> None:
    """``p``'s help ends with the paragraph ``make()``, made only when the help is shown (the
    viewer's keys import GLFW, which no other command line needs)."""
    plain = p.format_help

    def format_help() -> str:
        p.epilog = make()
        return plain()

    p.format_help = format_help


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``treeanim`` console script."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminated)  # `kill`: unwind, so temporary files are removed
    _plain_streams()
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
    except InputError as e:  # UsageError, PresetError, the offline jobs' own
        print(one_line(f"treeanim: error: {e}"), file=sys.stderr)
        return 2
    except OSError as e:  # a write that failed (disk full, name too long ...): the old file is kept
        if e.filename is None:  # standard output itself (`treeanim list > /dev/full`)
            _stdout_to_devnull()
        where = f"{e.filename}: " if e.filename is not None else ""
        print(one_line(f"treeanim: error: {where}{e.strerror or e}"), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("treeanim: interrupted", file=sys.stderr)
        return 130


def one_line(message: str) -> str:
    """An error message on one line, whatever it quotes (a path with a newline in it)."""
    return message.replace("\r", "\\r").replace("\n", "\\n")


def _plain_streams() -> None:
    """Standard output and error that never fail on a character: a closed one (`treeanim list
    >&-`) writes nowhere, one that cannot encode a character (`PYTHONIOENCODING=ascii`) writes
    it as an escape instead of raising after the work is done."""
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if stream is None:
            setattr(sys, name, open(os.devnull, "w", encoding="utf-8"))
        elif hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")


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
