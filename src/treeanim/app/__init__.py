"""The interactive viewer (``treeanim view``): a GLFW window with the tree in wind, pulled with the
mouse, tuned from an imgui panel.

Modules: :mod:`~treeanim.app.window` (the window and its GL context), :mod:`~treeanim.app.viewer`
(:class:`~treeanim.app.viewer.Viewer`: simulation, renderer, camera, input handlers, the main
loop), :mod:`~treeanim.app.gui` (imgui input and drawing), :mod:`~treeanim.app.panel` (the
settings panel; its settings are the table in :mod:`~treeanim.app.settings`, its key bindings the
table in :mod:`~treeanim.app.keys`), :mod:`~treeanim.app.input` (the input handlers),
:mod:`~treeanim.app.save` (save a preset TOML), :mod:`~treeanim.app.main`
(what the command line calls), :mod:`~treeanim.app.display` (whether a window can open here).
"""
