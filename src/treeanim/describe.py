"""What the command line says about trees and the viewer: the shipped presets a line each
(``treeanim list``), a tree's objects by number (``treeanim info --objects``: the numbers that
``--pull OBJECT:…``, ``--drag OBJECT…`` and ``trace --object`` take) and the viewer's mouse and
keys (``treeanim view --help``)."""

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
