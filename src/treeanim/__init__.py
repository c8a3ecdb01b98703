"""treeanim: interactive trees in wind and under the mouse (Hu, Chiba & He 2012).

The public API (docs/design.md §9)::

    import treeanim as ta
    tree = ta.load_preset("small_cherry")
    sim = ta.Simulation(tree, wind=ta.WindField(speed=5.0))
    sim.step(1 / 60)

Names are imported lazily so that ``import treeanim`` (and the command line) stays fast.
"""

from ._lazy import lazy_exports

__version__ = "0.1.0"

_EXPORTS = {
    "Tree": "model.tree",
    "Lamina": "model.tree",
    "PresetError": "errors",
    "InputError": "errors",
    "list_presets": "model.presets",
    "load_preset": "model.presets",
    "load_tree": "model.load",
    "load_scene": "model.scene_file",
    "list_scenes": "model.scene_file",
    "Scene": "model.scene",
    "make_scene": "model.scene",
    "place_tree": "model.scene",
    "SceneError": "errors",
    "load_qsm": "model.qsm",
    "WindField": "physics.wind",
    "fbm_noise": "physics.wind",
    "Simulation": "physics.simulation",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, globals(), _EXPORTS)
