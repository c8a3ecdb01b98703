"""The key table (app/keys.py) drives the viewer's handler and the panel's help: every binding
names a Viewer action, no key is bound twice, and the help lists every binding. The panel's
settings table (app/settings.py) names Viewer actions too."""

from __future__ import annotations

import glfw

from treeanim.app.keys import BINDINGS, MOUSE, binding_for, help_lines
from treeanim.app.settings import SETTINGS
from treeanim.app.viewer import Viewer


def test_every_binding_is_an_action_of_the_viewer_and_in_the_help():
    seen = set()
    text = "\n".join(help_lines())
    for b in BINDINGS:
        assert callable(getattr(Viewer, b.action, None)), b.action
        for key in b.keys:
            for shift in ((False, True) if b.shift is None else (b.shift,)):
                assert (key, b.ctrl, shift) not in seen, b
                seen.add((key, b.ctrl, shift))
        assert f"{b.label} {b.does}" in text
    assert all(f"{what}: {does}" in text for what, does in MOUSE)


def test_every_setting_of_the_panel_is_applied_by_a_viewer_method():
    """The panel changes nothing itself: each setting names the public Viewer method that
    applies it, and reads its value from public attributes (no private field on the way)."""
    for name, s in SETTINGS.items():
        assert not s.action.startswith("_") and callable(getattr(Viewer, s.action, None)), (name, s.action)
        assert getattr(Viewer, s.action).__doc__, (name, s.action)
        if isinstance(s.get, str):
            assert not any(part.startswith("_") for part in s.get.split(".")), (name, s.get)


def test_ctrl_picks_its_own_bindings():
    assert binding_for(glfw.KEY_S, 0).action == "request_screenshot"
    assert binding_for(glfw.KEY_S, glfw.MOD_CONTROL).action == "save_preset"
    assert binding_for(glfw.KEY_F, glfw.MOD_CONTROL) is None  # Ctrl with an unbound key does nothing
    assert binding_for(glfw.KEY_F12, glfw.MOD_SHIFT).action == "request_screenshot"
    assert binding_for(glfw.KEY_A, 0) is None


def test_shift_tells_undo_from_redo_and_digits_carry_their_number():
    ctrl, shift = glfw.MOD_CONTROL, glfw.MOD_SHIFT
    assert binding_for(glfw.KEY_Z, ctrl).action == "undo"
    assert binding_for(glfw.KEY_Z, ctrl | shift).action == "redo"
    assert binding_for(glfw.KEY_Y, ctrl).action == "redo"
    assert binding_for(glfw.KEY_Z, 0) is None
    b = binding_for(glfw.KEY_3, ctrl)
    assert (b.action, b.args(glfw.KEY_3)) == ("store_bookmark", (3,))
    b = binding_for(glfw.KEY_1, 0)
    assert (b.action, b.args(glfw.KEY_1)) == ("recall_bookmark", (1,))
    assert binding_for(glfw.KEY_5, 0) is None
    assert binding_for(glfw.KEY_D, 0).action == "toggle_draft"


def test_the_readme_lists_every_shortcut():
    """The README's viewer table is written by hand: it names every key of the table."""
    import re
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    table = readme[readme.index("| input | does |"):]
    rows = table[: table.index("\n\n")].splitlines()[2:]
    keys = {k for row in rows for k in re.split(r"\s+(?:·|or)\s+", row.split("|")[1].strip())}
    for b in BINDINGS:
        for key in b.label.split("/"):
            assert key in keys, (b.label, sorted(keys))
