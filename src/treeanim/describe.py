"""What the command line says about trees and the viewer: the shipped presets and scenes a line
each (``treeanim list``), a scene's trees (``treeanim info SCENE``), a tree's objects by number
(``treeanim info --objects``: the numbers that ``--pull OBJECT:…``, ``--drag OBJECT…`` and
``trace --object`` take) and the viewer's mouse and keys (``treeanim view --help``)."""

from __future__ import annotations


def preset_lines() -> list[str]:
    """One line per shipped preset: its name, height, objects and triangles (summer), and its
    description."""
    import tomllib
    from pathlib import Path

    import treeanim as ta

    rows = []
    for name in ta.list_presets():
        tree = ta.load_preset(name)
        stats = tree.stats(0.0)
        try:
            about = str(tomllib.loads(Path(tree.source).read_text("utf-8")).get("description", ""))
        except (OSError, ValueError):
            about = ""
        height = float(tree.rest_positions[:, 1].max())
        rows.append((name, f"{height:.1f} m tall", _count(stats["objects"], "object"),
                     _count(stats["triangles"], "triangle"), " ".join(about.split())))
    widths = [max(len(r[i]) for r in rows) for i in range(4)]
    return [f"{r[0]:<{widths[0]}}  {r[1]:>{widths[1]}}, {r[2]:>{widths[2]}}, {r[3]:>{widths[3]}}  {r[4]}".rstrip()
            for r in rows]


def scene_list_lines() -> list[str]:
    """One line per shipped scene: its name, its trees by kind (read from the file, none built)
    and its description."""
    from importlib import resources

    from .model.scene_file import list_scenes, scene_summary

    rows = []
    for name in list_scenes():
        with resources.as_file(resources.files("treeanim.presets") / "scenes" / f"{name}.toml") as path:
            n, per, about = scene_summary(path)
        kinds = ", ".join(f"{k:,} {_kind_name(t)}" for t, k in per.items())
        rows.append((name, f"scene of {_count(n, 'tree')} ({kinds})", about))
    width = max((len(r[0]) for r in rows), default=0)
    return [f"{r[0]:<{width}}  {r[1]}  {r[2]}".rstrip() for r in rows]


def _kind_name(tree: str) -> str:
    """A preset's name, or a tree file's name without its folder and suffix."""
    from pathlib import Path

    return Path(tree).stem


def scene_lines(scene, season: float) -> list[str]:
    """``treeanim info SCENE``: the scene's trees by kind, where they stand, and its objects,
    nodes and triangles by kind (the leaves present at ``season``)."""
    import numpy as np

    from .model.tree import KINDS, PLURAL

    stats = scene.stats(season)
    per: dict[str, int] = {}
    for p in scene.placements:
        per[_kind_name(p.tree)] = per.get(_kind_name(p.tree), 0) + 1
    where = np.array([p.position for p in scene.placements])
    scales = np.array([p.scale for p in scene.placements])
    lines = [f"{scene.name}: a scene of {_count(scene.n_trees, 'tree')} (season {season:g}, seed {scene.seed}) — "
             f"{scene.source}",
             "trees: " + ", ".join(f"{k:,} {t}" for t, k in per.items()),
             f"they stand over x {where[:, 0].min():.1f} … {where[:, 0].max():.1f} m, z {where[:, 2].min():.1f} … "
             f"{where[:, 2].max():.1f} m, scaled {scales.min():.2f} … {scales.max():.2f}; the tallest reaches "
             f"{scene.rest_positions[:, 1].max():.1f} m",
             f"{'object type':<12}{'objects':>10}{'nodes':>12}{'triangles':>14}"]
    for kind in KINDS:
        if stats[PLURAL[kind]]:
            lines.append(f"{kind:<12}{stats[PLURAL[kind]]:>10,}{stats[kind + '_nodes']:>12,}"
                         f"{stats[kind + '_triangles']:>14,}")
    lines.append(f"{'total':<12}{stats['objects']:>10,}{stats['nodes']:>12,}{stats['triangles']:>14,}")
    lines.append(f"objects are numbered 0 to {scene.n_objects - 1}, level by level over the whole scene, for "
                 "--pull OBJECT:... and --drag OBJECT...; --objects lists them")
    return lines


def _count(n: int, what: str) -> str:
    return f"{n:,} {what}{'s' * (n != 1)}"


def object_lines(tree) -> list[str]:
    """A table of ``tree``'s objects by number: kind, level, parent, nodes, length along its
    nodes (m), base diameter (cm) and tip (x, y, z in m, y up)."""
    from .model.geometry import object_lengths

    P = tree.rest_positions
    ends = tree.object_start + tree.object_count - 1
    length = object_lengths(tree)
    lines = [f"{'object':>7}  {'kind':<6}{'level':>6}{'parent':>8}{'nodes':>7}{'length m':>10}{'base cm':>9}"
             f"   tip x, y, z (m)"]
    for i in range(tree.n_objects):
        tip = ", ".join(f"{v:.2f}" for v in P[ends[i]])
        lines.append(f"{i:>7}  {tree.kind[i]:<6}{tree.level[i]:>6}{tree.parent[i]:>8}{tree.object_count[i]:>7}"
                     f"{length[i]:>10.3f}{100 * tree.node_diameter[tree.object_start[i]]:>9.2f}   {tip}")
    return lines


def viewer_controls() -> str:
    """The viewer's mouse and keys as one paragraph (from :mod:`treeanim.app.keys`)."""
    try:
        from .app.keys import BINDINGS, MOUSE
    except Exception:  # noqa: BLE001 - no GLFW library here: the README has the table
        return "Mouse and keys: see the README's table 'The viewer'."
    mouse = "; ".join(f"{what}: {does}" for what, does in MOUSE)
    keys = "; ".join(f"{b.label} {b.does}" for b in BINDINGS)
    return f"Mouse: {mouse}. Keys: {keys}."
