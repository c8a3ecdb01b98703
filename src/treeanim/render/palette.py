"""The colours of leaves (summer through autumn), petioles and grass blades, sRGB in [0, 1]:
written once here, injected into the vertex shader (``constants.glsl``, see
:mod:`treeanim.render.shaders`) and used by the glTF exporter's vertex colours."""

LEAF_DARK = (0.13, 0.33, 0.05)  # summer, from dark to light by the leaf's jitter ...
LEAF_LIGHT = (0.33, 0.55, 0.10)
LEAF_COOL = (0.24, 0.46, 0.16)  # ... and a little of this by its second jitter
LEAF_YELLOW = (0.88, 0.70, 0.12)  # autumn, in this order
LEAF_ORANGE = (0.92, 0.40, 0.06)
LEAF_RED = (0.70, 0.10, 0.06)
LEAF_BROWN = (0.40, 0.17, 0.06)
LEAF_DRY = (0.50, 0.40, 0.27)  # winter: the few leaves a cherry keeps, withered (docs/design.md §3)
PETIOLE = (0.55, 0.28, 0.14)  # mixed 40 % into the leaf's colour
BLADE_BASE = (0.17, 0.33, 0.07)  # a blade from its base to its tip, the tip between a fresh ...
BLADE_TIP = (0.46, 0.66, 0.18)
BLADE_TIP_DRY = (0.66, 0.68, 0.30)  # ... and a sun-dried green by the blade's jitter
BLADE_WINTER = (0.62, 0.55, 0.32)
HIGHLIGHT = (0.85, 0.15, 1.0)  # the grabbed object's tint: a violet no leaf, blade or bark takes

#: Every colour above, by name (the shader's constants).
COLOURS = {name: value for name, value in globals().items() if name.isupper() and isinstance(value, tuple)}
