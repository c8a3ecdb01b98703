"""Save the viewer's settings as a preset TOML, and load them back.

A saved file is a preset like those in ``assets/presets/``: the original preset's document
edited through tomlkit, so its tables, keys, comments and order stay as they were; the
top-level ``seed`` and the ``[physics]`` values that changed are set in place, a setting the
original left at its default is added only when it differs from it, and a kind's f/ζ range is
added as an inline table like the shipped presets'. What is written is read back with the
preset reader and must give the same physics before it replaces anything, and it is written
atomically (:func:`treeanim.files.atomic_path`: a temporary file in the same folder, then a
rename), so an interrupted save never leaves a half-written preset. ``treeanim.load_tree(path)``
loads it. Every value a :class:`~treeanim.model.params.PhysicsParams` can hold can be saved:
both check the same declarations.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

import tomlkit

from ..errors import PresetError
from ..files import atomic_path
from ..model.declare import default_of
from ..model.params import PARAMS, PhysicsParams
from ..model.scene import Scene
from ..model.tree import KINDS, Tree

__all__ = ["physics_toml", "preset_text", "save_preset", "original_preset_text"]


def _put(table, key: str, value) -> None:
    """Set ``table[key]`` unless it already holds ``value`` (so its text and comment stay)."""
    if key not in table or table[key].unwrap() != value:
        table[key] = value


def _write_physics(table, physics: PhysicsParams, every: bool) -> None:
    """Write ``physics`` into the [physics] ``table`` of a tomlkit document: the scalars it has,
    and those that differ from their defaults (all of them where ``every``); the f and ζ ranges
    per season and kind."""
    for name in PARAMS:
        value = getattr(physics, name)
        if name in table or every or value != default_of(PhysicsParams, name):
            _put(table, name, value)
    for season in ("summer", "winter"):
        if season not in table:
            table[season] = tomlkit.table()
        modes = table[season]
        for kind in KINDS:
            r = getattr(physics, season).of(kind)
            if r is None:
                if kind in modes:
                    del modes[kind]
            elif kind not in modes:
                row = tomlkit.inline_table()
                row.update({"f": list(r.f), "zeta": list(r.zeta)})
                modes[kind] = row
            else:
                for what in ("f", "zeta"):
                    _put(modes[kind], what, list(getattr(r, what)))


def physics_toml(physics: PhysicsParams) -> str:
    """The ``[physics]`` tables of a preset for ``physics``, every setting written (exact: floats
    are written by repr)."""
    doc = tomlkit.document()
    doc["physics"] = tomlkit.table()
    _write_physics(doc["physics"], physics, every=True)
    return tomlkit.dumps(doc)


def original_preset_text(tree: Tree) -> str:
    """The text of the preset file ``tree`` was generated from.

    Raises
    ------
    ValueError
        The tree has no readable source file (e.g. it was built in code).
    """
    if isinstance(tree, Scene):
        raise ValueError(f"{tree.name!r} is a scene of {tree.n_trees} trees; its physics are its trees' presets' "
                         "(open one of them to save its physics)")
    if tree.source and not tree.source.endswith(".toml"):
        raise ValueError(f"tree {tree.name!r} was loaded from {tree.source}, not a preset file; there is no "
                         "preset shape to save its physics with")
    if tree.source:
        try:
            return Path(tree.source).read_text(encoding="utf-8")
        except OSError:
            pass
    try:  # a shipped preset read through a temporary copy that is gone now
        from ..model.presets import list_presets

        if tree.name in list_presets():
            return (resources.files("treeanim.presets") / f"{tree.name}.toml").read_text(encoding="utf-8")
    except OSError:  # pragma: no cover
        pass
    raise ValueError(f"tree {tree.name!r} was not loaded from a preset file; there is no shape to save")


def preset_text(original: str, physics: PhysicsParams, seed: int | None = None) -> str:
    """A preset's text: ``original`` with its physics and its top-level seed set.

    The document is edited in place (tomlkit), so everything else keeps its text, comments and
    order, whatever the layout (tables, dotted keys, inline tables). The result parses to the
    original's data except for ``physics`` and ``seed``.
    """
    doc = tomlkit.parse(original)
    if seed is not None:
        _put(doc, "seed", int(seed))
    if "physics" not in doc:
        doc["physics"] = tomlkit.table()
    _write_physics(doc["physics"], physics, every=False)
    return tomlkit.dumps(doc)


def save_preset(path, tree: Tree, physics: PhysicsParams, seed: int | None = None) -> Path:
    """Write ``tree``'s preset with ``physics`` (and ``seed``, default the tree's) to ``path``.

    The file is read back with the preset reader (it must give ``physics`` again), then moved
    into place atomically.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        No source preset, an unwritable folder, or values a preset cannot hold (the message is
        one line).
    """
    path = Path(path).expanduser()
    if path.suffix.lower() != ".toml":
        raise ValueError(f"{path}: a preset file must end in .toml")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"{path}: folder {folder} does not exist")
    text = preset_text(original_preset_text(tree), physics, tree.seed if seed is None else seed)
    from ..model.presets import read_spec

    try:
        with atomic_path(path, ".toml") as tmp:
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(text)
                f.flush()
                os.fsync(f.fileno())
            try:
                back = read_spec(tmp).physics
            except PresetError as e:
                raise ValueError(str(e).replace(str(tmp), str(path))) from None
            if back != physics:  # pragma: no cover - a writer bug, never a user's value
                raise ValueError(f"{path}: the saved physics read back differently; nothing was written")
    except OSError as e:
        raise ValueError(f"{path}: cannot write in {folder} ({e.strerror or e})") from None
    return path
