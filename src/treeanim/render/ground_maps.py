"""The ground's detail maps: tileable noise that ``shaders/ground.frag`` reads as a mipmapped
(trilinear) texture, so the ground keeps its grain where a pixel spans little of it and fades
to its mean colour where a pixel spans more (far away: no blotches smeared along the view, as
the noise of coarse octaves left there did). Anisotropic filtering would keep more detail far
away, but llvmpipe takes minutes a frame for it at grazing angles.

One RGBA8 image that repeats at its edges, each channel band-limited noise in 0 .. 1 about
0.5 (white noise shaped in the frequency domain, so it tiles):

- R, tufts: grass a few texels across;
- G, patches: blobs a tenth of the tile across, the soil's outline;
- B, grain: clods and pebbles, a texel or two across;
- A, tint: grass a little larger than R's, for its dry and green shades.

Made with numpy at first use, the same image every time (a fixed seed), and kept
(:func:`ground_maps`).
"""

from __future__ import annotations

import moderngl
import numpy as np

#: Texels a side.
SIZE = 256
#: Each channel's wavelengths, in texels: (shortest, longest).
BANDS = ((3.0, 24.0), (18.0, 80.0), (1.5, 6.0), (6.0, 40.0))

_cache: dict[int, np.ndarray] = {}


def _band_noise(rng: np.random.Generator, size: int, shortest: float, longest: float) -> np.ndarray:
    """Tileable noise with wavelengths from ``shortest`` to ``longest`` texels, in 0 .. 1
    about 0.5 (its standard deviation 0.2)."""
    f = np.fft.fftfreq(size)
    k = np.hypot(f[:, None], f[None, :])
    keep = (k >= 1.0 / longest) & (k <= 1.0 / shortest)
    spectrum = np.fft.fft2(rng.standard_normal((size, size))) * keep / np.maximum(k, 1e-6) ** 0.5
    n = np.real(np.fft.ifft2(spectrum))
    return np.clip(0.5 + 0.5 * n / (2.5 * n.std()), 0.0, 1.0)


def make_ground_maps(size: int = SIZE) -> np.ndarray:
    """The maps (module notes), computed (:func:`ground_maps` keeps them).

    Returns
    -------
    (size, size, 4) uint8
    """
    rng = np.random.default_rng(30)
    maps = [_band_noise(rng, size, *band) for band in BANDS]
    return np.round(255.0 * np.stack(maps, axis=-1)).astype(np.uint8)


def ground_maps(size: int = SIZE) -> np.ndarray:
    """The maps (:func:`make_ground_maps`), made once and kept.

    Returns
    -------
    (size, size, 4) uint8, read-only
    """
    if size not in _cache:
        maps = make_ground_maps(size)
        maps.flags.writeable = False
        _cache[size] = maps
    return _cache[size]


def ground_texture(ctx: moderngl.Context) -> moderngl.Texture:
    """The maps (:func:`ground_maps`) as a texture: mipmapped, trilinear, repeating."""
    maps = ground_maps()
    texture = ctx.texture(maps.shape[1::-1], 4, maps.tobytes())
    texture.build_mipmaps()
    texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = True
    return texture
