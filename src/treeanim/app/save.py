"""Save the viewer's settings as a preset TOML, and load them back.

A saved file is a preset like those in ``assets/presets/``: the original preset's text with
its shape tables (trunk, levels, leaves, lamina, grass, beam) and comments kept as they were,
the top-level ``seed`` set, and the ``[physics]`` tables replaced by the current values. It is
checked with the preset reader before it replaces anything, and written atomically
(:func:`treeanim.files.atomic_path`: a temporary file in the same folder, then a rename), so an
interrupted save never leaves a half-written preset. ``treeanim.load_tree(path)`` loads it.
"""

from __future__ import annotations

import os
import re
import tomllib
from importlib import resources
from pathlib import Path

from ..errors import PresetError
from ..files import atomic_path
from ..model.params import SCALAR_KEYS, PhysicsParams
from ..model.tree import KINDS, Tree
from ..validate import finite_float, positive_float

__all__ = ["physics_toml", "preset_text", "save_preset", "original_preset_text"]

_HEADER = re.compile(r"^\s*\[\[?\s*([A-Za-z0-9_.\"' -]+?)\s*\]\]?\s*(#.*)?$")
_TOP_SEED = re.compile(r"^\s*seed\s*=")


def _num(x: float) -> str:
    return repr(finite_float("a number written into a preset", x))


def physics_toml(physics: PhysicsParams) -> str:
    """The ``[physics]`` tables of a preset for ``physics`` (exact: floats written by repr).

    Raises
    ------
    ValueError
        A scalar the preset format cannot hold (it must be finite and > 0).
    """
    lines = ["[physics]"]
    for k in SCALAR_KEYS:
        v = positive_float(f"physics.{k}", getattr(physics, k))  # the preset format holds no other
        lines.append(f"{k} = {v!r}")
    for season in ("summer", "winter"):
        modes = getattr(physics, season)
        lines += ["", f"[physics.{season}]"]
        for kind in KINDS:
            r = modes.of(kind)
            if r is None:
                continue
            lines.append(f"{kind} = {{ f = [{_num(r.f[0])}, {_num(r.f[1])}], "
                         f"zeta = [{_num(r.zeta[0])}, {_num(r.zeta[1])}] }}")
    return "\n".join(lines) + "\n"


def original_preset_text(tree: Tree) -> str:
    """The text of the preset file ``tree`` was generated from.

    Raises
    ------
    ValueError
        The tree has no readable source file (e.g. it was built in code).
    """
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


def _strip_physics(text: str) -> tuple[list[str], int]:
    """Lines of ``text`` without its physics tables, and the index of the first table header."""
    out: list[str] = []
    skipping = False
    first_header = None
    for line in text.splitlines():
        m = _HEADER.match(line)
        if m:
            name = m.group(1).replace('"', "").replace("'", "").replace(" ", "")
            skipping = name == "physics" or name.startswith("physics.")
            if first_header is None and not skipping:
                first_header = len(out)
        if not skipping:
            out.append(line)
    if first_header is None:
        first_header = len(out)
    return out, first_header


def preset_text(original: str, physics: PhysicsParams, seed: int | None = None) -> str:
    """A preset's text: ``original`` with its physics replaced and its top-level seed set.

    The shape tables keep their text (and comments) where the original's physics sits in
    tables of their own, as in the shipped presets; otherwise the whole file is rewritten from
    its parsed values. Either way the result parses to the original's data except for
    ``physics`` and ``seed``.
    """
    data = tomllib.loads(original)
    lines, first = _strip_physics(original)
    if seed is not None:
        seed = int(seed)
        head = lines[:first]
        for i, line in enumerate(head):
            if _TOP_SEED.match(line):
                lines[i] = f"seed = {seed}"
                break
        else:
            lines.insert(first, f"seed = {seed}\n" if first < len(lines) else f"seed = {seed}")
    while lines and not lines[-1].strip():
        lines.pop()
    text = "\n".join(lines) + "\n\n" + physics_toml(physics)
    want = {k: v for k, v in data.items() if k != "physics"}
    if seed is not None:
        want["seed"] = seed
    try:
        got = tomllib.loads(text)
        ok = {k: v for k, v in got.items() if k != "physics"} == want
    except tomllib.TOMLDecodeError:
        ok = False
    if not ok:  # an unusual layout (physics in dotted keys, inline tables ...): rewrite it all
        text = _dump(want) + "\n" + physics_toml(physics)
    return text


def save_preset(path, tree: Tree, physics: PhysicsParams, seed: int | None = None) -> Path:
    """Write ``tree``'s preset with ``physics`` (and ``seed``, default the tree's) to ``path``.

    The file is checked with the preset reader, then moved into place atomically.

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
                read_spec(tmp)
            except PresetError as e:
                raise ValueError(str(e).replace(str(tmp), str(path))) from None
    except OSError as e:
        raise ValueError(f"{path}: cannot write in {folder} ({e.strerror or e})") from None
    return path


# ---------------------------------------------------------------------------- fallback writer
def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return _num(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise ValueError(f"cannot write {type(v).__name__} into a preset")


def _key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _value(k)


def _dump(data: dict) -> str:
    """A TOML text of ``data`` (scalars, arrays, tables, arrays of tables)."""
    lines: list[str] = []
    tables: list[tuple[str, dict]] = []
    arrays: list[tuple[str, list]] = []
    for k, v in data.items():
        if isinstance(v, dict):
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            arrays.append((k, v))
        else:
            lines.append(f"{_key(k)} = {_value(v)}")
    for k, v in tables:
        lines += ["", f"[{_key(k)}]"] + [f"{_key(a)} = {_value(b)}" for a, b in v.items()]
    for k, v in arrays:
        for item in v:
            lines += ["", f"[[{_key(k)}]]"] + [f"{_key(a)} = {_value(b)}" for a, b in item.items()]
    return "\n".join(lines) + "\n"
