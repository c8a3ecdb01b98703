"""The interactive viewer (``treeanim view``): a GLFW window with the tree in wind, pulled with the
mouse, tuned from an imgui panel.

Modules: :mod:`~treeanim.app.window` (the window and its GL context), :mod:`~treeanim.app.viewer`
(:class:`~treeanim.app.viewer.Viewer`: simulation, renderer, camera, pulls, the main loop),
:mod:`~treeanim.app.input` (its input handlers), :mod:`~treeanim.app.keys` (the key bindings'
table), :mod:`~treeanim.app.gui` (imgui input and drawing), :mod:`~treeanim.app.panel` (the
settings panel), :mod:`~treeanim.app.settings` (the panel's settings' table),
:mod:`~treeanim.app.save` (save a preset TOML), :mod:`~treeanim.app.main` (what the command line
calls), :mod:`~treeanim.app.display` (whether a window can open here).
"""
