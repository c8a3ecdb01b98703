"""The ``treeanim`` command line: view | info | render | trace | bench | export.

Every subcommand reports bad input as one line on stderr and exits with status 2.
"""

from __future__ import annotations

import argparse
import sys

#: The paper's Table 1, per preset: rows of (kind, objects, nodes, triangles, fmin, fmax, ζmin, ζmax).
TABLE1 = {
    "small_cherry": [("branch", 60, 123, 3936, 0.5, 1.0, 0.2, 0.5), ("leaf", 816, 3264, 115056, 1.2, 1.8, 0.08, 0.12)],
    "large_cherry": [("branch", 546, 1160, 37120, 0.4, 0.8, 0.12, 0.30), ("leaf", 5460, 21840, 769860, 1.0, 1.4, 0.08, 0.12)],
    "large_cherry@winter": [("branch", 546, 1160, 37120, 0.6, 1.3, 0.07, 0.15), ("leaf", 344, 1376, 48504, 1.6, 2.8, 0.03, 0.07)],
    "tulip_poplar": [("branch", 322, 1410, 45120, 0.4, 0.5, 0.12, 0.14), ("leaf", 1932, 9660, 241500, 1.3, 1.7, 0.07, 0.09)],
    "grassland": [("blade", 5000, 20000, 35000, 0.8, 1.2, 0.13, 0.17)],
}
#: The paper's frame rates (Table 1, Core2 Duo 2.8 GHz + GeForce 9500 GT).
TABLE1_FPS = {"small_cherry": 45, "large_cherry": 10, "large_cherry@winter": 41, "tulip_poplar": 20, "grassland": 23}

PLURAL = {"branch": "branches", "leaf": "leaves", "blade": "blades"}

#: What plain ``treeanim`` runs.
DEFAULT_COMMAND = ["info", "small_cherry"]


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


def _positive(kind):
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a positive {kind.__name__}, got {text!r}") from None
        if not (value > 0 and value < float("inf")):
            raise argparse.ArgumentTypeError(f"expected a positive {kind.__name__}, got {text!r}")
        return value

    return parse


def _non_negative(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 <= value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return value


def _vector(text: str):
    from treeanim.scripted import parse_vector

    try:
        return parse_vector(text, "direction")
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def _pull(text: str):
    from treeanim.scripted import parse_pull

    try:
        return parse_pull(text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def add_scene_options(p: argparse.ArgumentParser, seconds: float = 5.0, fps: float = 30.0) -> None:
    """Options shared by the offline commands: the preset, timing, wind, season and pulls."""
    p.add_argument("preset", help="preset name (see 'treeanim list') or path to a preset .toml")
    p.add_argument("--seconds", type=_positive(float), default=seconds, help=f"duration in seconds (default {seconds:g})")
    p.add_argument("--fps", type=_positive(float), default=fps, help=f"frames per second (default {fps:g})")
    p.add_argument("--wind", type=_non_negative, default=5.0, metavar="SPEED",
                   help="wind speed at the tree top, m/s (default 5; 0 = calm)")
    p.add_argument("--wind-dir", type=_vector, default=(1.0, 0.0, 0.0), metavar="X,Y,Z",
                   help="wind direction; needs a horizontal part (default 1,0,0)")
    p.add_argument("--turbulence", type=float, default=1.5, metavar="LAMBDA", help="λ of Eq. 17, in [1, 2] (default 1.5)")
    p.add_argument("--season", type=_season, default=0.0, help="0 = summer … 1 = winter (default 0)")
    p.add_argument("--seed", type=int, default=0, help="seed of the wind and the modal noise (default 0)")
    p.add_argument("--pull", type=_pull, action="append", default=[], metavar="OBJECT:FX,FY,FZ@T0-T1",
                   help="pull OBJECT's tip with a world force in newtons from T0 to T1 s, then let go; repeatable")


def make_simulation(args):
    """The tree and a Simulation set up from :func:`add_scene_options`."""
    import treeanim as ta
    from treeanim.scripted import check_pulls

    tree = load_any(args.preset)
    try:
        check_pulls(args.pull, tree.n_objects)
        wind = None
        if args.wind > 0:
            wind = ta.WindField(direction=args.wind_dir, speed=args.wind, turbulence=args.turbulence, seed=args.seed)
        sim = ta.Simulation(tree, wind=wind, season=args.season, seed=args.seed)
    except ValueError as e:
        raise UsageError(str(e)) from None
    return tree, sim


def output_path(text: str, suffixes: tuple[str, ...]):
    """Check an output path: a known extension and a writable folder."""
    import os
    from pathlib import Path

    path = Path(text)
    if path.suffix.lower() not in suffixes:
        raise UsageError(f"--out {text}: unknown extension {path.suffix or '(none)'!r}; expected {', '.join(suffixes)}")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise UsageError(f"--out {text}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise UsageError(f"--out {text}: folder {folder} is not writable")
    return path


def cmd_export(args) -> int:
    """Bake the simulated motion into a glTF 2.0 file."""
    import numpy as np
    from tqdm import tqdm

    from treeanim import export, scripted

    out = output_path(args.out, (".glb", ".gltf"))
    tree, sim = make_simulation(args)
    skel = export.skeleton(tree)
    fade = int(round(args.loop * args.fps))
    n = int(round(args.seconds * args.fps))
    if n < 2:
        raise UsageError(f"--seconds {args.seconds:g} at --fps {args.fps:g} gives fewer than 2 frames")
    if fade >= n:
        raise UsageError(f"--loop {args.loop:g}: the cross-fade must be shorter than --seconds")
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


def load_any(name_or_path: str):
    """A preset by name, or a preset TOML file by path."""
    import treeanim as ta

    if name_or_path.endswith(".toml"):
        return ta.load_tree(name_or_path)
    return ta.load_preset(name_or_path)


def cmd_info(args) -> int:
    """Print a preset's statistics beside the paper's Table 1 row."""
    tree = load_any(args.preset)
    stats = tree.stats(args.season)
    key = tree.name + ("@winter" if args.season >= 1.0 and tree.name == "large_cherry" else "")
    paper = {row[0]: row for row in TABLE1.get(key, [])}
    params = tree.physics
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
        mr = f"{modes.f[0]:.2f}–{modes.f[1]:.2f}  {modes.zeta[0]:.2f}–{modes.zeta[1]:.2f}" if modes else ""
        print(
            f"{kind:<12}{n:>7,} / {ref(1):>6}{stats[kind + '_nodes']:>8,} / {ref(2):>7}"
            f"{stats[kind + '_triangles']:>11,} / {ref(3):>8}   {mr}"
        )
    total_p = sum(r[2] for r in paper.values()), sum(r[3] for r in paper.values())
    print(f"{'total':<12}{stats['objects']:>7,}{'':>9}{stats['nodes']:>8,} / {total_p[0]:>7,}"
          f"{stats['triangles']:>11,} / {total_p[1]:>8,}")
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
    p.add_argument("--season", type=_season, default=0.0, help="0 = summer … 1 = winter (default 0)")
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

    p = sub.add_parser("list", help="list the shipped presets", description="List the shipped presets.")
    p.set_defaults(func=lambda args: print("\n".join(__import__("treeanim").list_presets())) or 0)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``treeanim`` console script."""
    from treeanim.model.errors import PresetError

    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        args = parser.parse_args(DEFAULT_COMMAND)
    try:
        return int(args.func(args) or 0)
    except (PresetError, UsageError) as e:
        print(f"treeanim: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("treeanim: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
