"""Whether a window can be opened here (importable without GLFW, OpenGL or imgui)."""

from __future__ import annotations

import os
import sys

from ..errors import ViewerUnavailable

#: What to use where no window can be opened.
HEADLESS_HINT = ("the headless commands need no window: 'treeanim render PRESET --out FILE' "
                 "(images, video) and 'treeanim export PRESET --out FILE.glb'")


def check_display() -> None:
    """Raise :class:`ViewerUnavailable` on Linux when neither X11 nor Wayland is reachable."""
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise ViewerUnavailable(f"no display to open a window on (DISPLAY and WAYLAND_DISPLAY are unset); "
                                f"{HEADLESS_HINT}")
