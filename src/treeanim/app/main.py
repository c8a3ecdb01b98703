"""``treeanim view``: open the window, run the viewer until it is closed."""

from __future__ import annotations

from ..errors import ViewerUnavailable
from .display import HEADLESS_HINT, check_display


def view(tree, *, season: float = 0.0, wind_speed: float | None = None, wind_preset: str | None = None, size: tuple[int, int] = (1280, 720),
         frames: int | None = None, samples: int | None = None, title: str | None = None) -> int:
    """Show ``tree`` in a new window until the user closes it (or ``frames`` frames are drawn).

    ``samples``: MSAA samples (None: 4, or none on a software rasteriser; see
    :meth:`Window.open`).

    Returns
    -------
    int
        Frames drawn.

    Raises
    ------
    ViewerUnavailable
        No display, no GLFW, no OpenGL 3.3, or the viewer's libraries cannot load (one line).
    ValueError
        The tree cannot be simulated or shown as asked (e.g. its physics has no f/ζ range for
        a kind the tree has, or a wind speed out of range): one line naming the tree; the
        window is closed again and nothing is left behind.
    """
    check_display()  # before loading GLFW, OpenGL and imgui: the clearest message
    try:
        from .viewer import Viewer, run
        from .window import Window
    except (ImportError, OSError) as e:  # e.g. imgui-bundle's, GLFW's or OpenGL's shared libraries
        raise ViewerUnavailable(f"the viewer's libraries cannot load ({' '.join(str(e).split())}); "
                                f"{HEADLESS_HINT}") from None
    win = Window.open(*size, title or f"treeanim — {tree.name}", samples=samples)
    try:
        try:
            viewer = Viewer(win, tree, season=season, wind_speed=wind_speed, wind_preset=wind_preset)
        except ValueError as e:
            raise ValueError(f"cannot show {getattr(tree, 'name', 'the tree')}: {' '.join(str(e).split())}") from None
        try:
            return run(viewer, max_frames=frames)
        finally:
            viewer.release()
    finally:
        win.close()
