"""One reader for every tree file and name: a TreeQSM model by its suffix, else a TOML file by
its ``type`` (a scene or a preset). ``treeanim.load_tree``, the command line (``cli.load_any``)
and the viewer's Open read through it, so all three take the same files and refuse the same
things in the same words (docs/design.md §14, §17).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import PresetError
from .presets import list_presets, load_preset, read_toml, read_tree
from .qsm.convert import load_qsm
from .qsm.leaves import LEAVES_FOR_QSM_ONLY
from .qsm.read import QSM_SUFFIXES
from .scene_file import list_scenes, load_scene, read_scene
from .tree import Tree

__all__ = ["load_tree", "load_named", "FILE_SUFFIXES"]

#: What names a file rather than a shipped preset or scene: a preset or scene TOML, a TreeQSM model.
FILE_SUFFIXES = (".toml", *QSM_SUFFIXES)


def _no_leaves(what: str, leaves: str | None) -> None:
    """Refuse leaves for anything but a TreeQSM model (a preset, and so a scene, has its own)."""
    if leaves not in (None, "none"):
        raise PresetError(f"{what}: {LEAVES_FOR_QSM_ONLY}")


def load_tree(path: str | Path, leaves: str | None = None) -> Tree:
    """Read any tree file: a TreeQSM model by its suffix (:data:`QSM_SUFFIXES`:
    :func:`~treeanim.model.qsm.load_qsm`), else a TOML file by its ``type``: a scene
    (:func:`~treeanim.model.scene_file.read_scene`) or a preset
    (:func:`~treeanim.model.presets.read_tree`).

    Parameters
    ----------
    path : str or Path
    leaves : str or None
        A TreeQSM model's leaves (:func:`~treeanim.model.qsm.parse_leaves`); a preset or a
        scene has its own, so anything but None or 'none' is refused for one.

    Returns
    -------
    Tree
        A :class:`~treeanim.model.scene.Scene` for a scene file.

    Raises
    ------
    PresetError
        One line naming the file, the key or row and what was expected (a QSMError for a
        TreeQSM model, a SceneError for a scene).
    """
    if str(path).lower().endswith(QSM_SUFFIXES):
        return load_qsm(path, leaves=leaves)
    _no_leaves(str(path), leaves)
    data = read_toml(path)
    if data.get("type") == "scene":
        return read_scene(path, data)
    return read_tree(path, data)


def load_named(name_or_path: str, leaves: str | None = None) -> Tree:
    """A shipped preset or scene by name, or any tree file by path (:func:`load_tree`); a
    name that is both is the preset.

    Raises
    ------
    PresetError
        An unknown name (listing the presets and scenes), leaves for anything but a TreeQSM
        model, or an unusable file.
    """
    text = str(name_or_path)
    if text.lower().endswith(FILE_SUFFIXES):
        return load_tree(text, leaves=leaves)
    _no_leaves(text, leaves)
    if text in list_presets():
        return load_preset(text)
    if text in list_scenes():
        return load_scene(text)
    raise PresetError(f"unknown preset or scene {text!r}; presets: {', '.join(list_presets())}; scenes: "
                      f"{', '.join(list_scenes())}")
