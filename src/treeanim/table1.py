"""The paper's Table 1 (Hu, Chiba & He 2012): the counts, modal ranges and frame rates the
presets are measured against (``treeanim info``, ``treeanim bench``, tests/test_model.py)."""

#: The paper's Table 1, per preset: rows of (kind, objects, nodes, triangles, fmin, fmax, ζmin, ζmax).
TABLE1 = {
    "small_cherry": [("branch", 60, 123, 3936, 0.5, 1.0, 0.2, 0.5), ("leaf", 816, 3264, 115056, 1.2, 1.8, 0.08, 0.12)],
    "large_cherry": [("branch", 546, 1160, 37120, 0.4, 0.8, 0.12, 0.30), ("leaf", 5460, 21840, 769860, 1.0, 1.4, 0.08, 0.12)],
    "large_cherry@winter": [("branch", 546, 1160, 37120, 0.6, 1.3, 0.07, 0.15), ("leaf", 344, 1376, 48504, 1.6, 2.8, 0.03, 0.07)],
    "tulip_poplar": [("branch", 322, 1410, 45120, 0.4, 0.5, 0.12, 0.14), ("leaf", 1932, 9660, 241500, 1.3, 1.7, 0.07, 0.09)],
    "grassland": [("blade", 5000, 20000, 35000, 0.8, 1.2, 0.13, 0.17)],
}
#: The paper's frame rates (Table 1, Core2 Duo 2.8 GHz + GeForce 9500 GT).
TABLE1_FPS = {"small_cherry": 45, "large_cherry": 10, "large_cherry@winter": 41, "tulip_poplar": 20, "grassland": 23}

#: Each row's preset and season (the rows the benchmark measures, in order).
ROWS = {
    "small_cherry": ("small_cherry", 0.0),
    "large_cherry": ("large_cherry", 0.0),
    "large_cherry@winter": ("large_cherry", 1.0),
    "tulip_poplar": ("tulip_poplar", 0.0),
    "grassland": ("grassland", 0.0),
}
