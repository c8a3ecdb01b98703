"""treeanim: interactive trees in wind and under the mouse (Hu, Chiba & He 2012).

The public API (DESIGN §9)::

    import treeanim as ta
    tree = ta.load_preset("small_cherry")
    sim = ta.Simulation(tree, wind=ta.WindField(speed=5.0))
    sim.step(1 / 60)

Names are imported lazily so that ``import treeanim`` (and the command line) stays fast.
"""

from importlib import import_module

__version__ = "0.1.0"

_EXPORTS = {
    "Tree": "treeanim.model.tree",
    "Lamina": "treeanim.model.tree",
    "PresetError": "treeanim.model.errors",
    "list_presets": "treeanim.model.presets",
    "load_preset": "treeanim.model.presets",
    "load_tree": "treeanim.model.presets",
    "WindField": "treeanim.physics.wind",
    "fbm_noise": "treeanim.physics.wind",
    "Simulation": "treeanim.physics.simulation",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'treeanim' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
