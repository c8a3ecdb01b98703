"""The interactive viewer (``treeanim view``): the tree in wind in a window, pulled with the mouse,
tuned from an imgui panel; the same app runs in a GLFW window or headless on EGL.

Modules: :mod:`~treeanim.app.protocol` (:class:`~treeanim.app.protocol.AppWindow`, what the
viewer needs of a window), :mod:`~treeanim.app.window` (the GLFW window and its GL context),
:mod:`~treeanim.app.headless` (the headless window: an EGL context and an offscreen
framebuffer), :mod:`~treeanim.app.viewer` (:class:`~treeanim.app.viewer.Viewer`: simulation,
renderer, camera, pulls, the frame, the main loop), :mod:`~treeanim.app.input` (its input
handlers), :mod:`~treeanim.app.actions` (its actions: what the panel, the keys and scripts do),
:mod:`~treeanim.app.keys` (the key bindings' table), :mod:`~treeanim.app.gui` (imgui input and
drawing), :mod:`~treeanim.app.panel` (the settings panel), :mod:`~treeanim.app.settings` (the
panel's settings' table), :mod:`~treeanim.app.save` (save a preset TOML),
:mod:`~treeanim.app.main` (what the command line calls), :mod:`~treeanim.app.display` (whether a
window can open here).
"""
