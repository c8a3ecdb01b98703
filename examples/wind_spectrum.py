"""Plot the wind's measured spectra and a vertical slice of wind speed, for the default
physical wind (the one the viewer and every command use) or, with ``--paper``, the paper's
field (its Fig. 7b).

    .venv/bin/python examples/wind_spectrum.py --out out/            # the physical wind
    .venv/bin/python examples/wind_spectrum.py --paper --out out/    # the paper's field

writes two PNGs:

* ``wind_spectrum.png`` — physical: the power spectra of the three components (u along the
  wind, v vertical, w lateral) at fixed points at the canopy top over ``--seconds`` of wind,
  against the von Kármán shape (f² + f0²)^−β/2 of each component's length scale (f0 =
  U / (2π·1.339·L_c), L_c = L for u and L/3 for v, w), with the slope fitted in the inertial
  range. Paper: the 1-D power spectra of the three noise grids, averaged over all grid lines
  and the three axes, against k^−β, with the slope fitted over k = 2 … N/8;
* ``wind_slice.png`` — wind speed on the vertical plane through the wind, with arrows, and
  beside it the mean speed per height: physical, the mean along-wind speed and σ_u against
  the canopy profile (exponential inside the canopy, logarithmic above); paper, the mean speed
  against the log profile c1·ln(c2·h) of Eq. 16, averaged over 8 seeds (drawn at the nominal
  speed, and least-squares scaled: Eq. 17's turbulence factor averages a little below 1).

Needs matplotlib: ``.venv/bin/pip install -e '.[plots]'`` from the repository, then
``.venv/bin/python examples/wind_spectrum.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

try:
    import treeanim  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import numpy as np

from treeanim.offline.trace import PLOTS_HINT, pyplot, save_figure
from treeanim.physics.wind import WindField


def axis_spectrum(field: np.ndarray) -> np.ndarray:
    """1-D periodogram along each axis, averaged over lines and axes; k = 0 … n/2."""
    out = []
    for axis in range(3):
        p = np.abs(np.fft.rfft(field, axis=axis)) ** 2
        out.append(p.mean(axis=tuple(a for a in range(3) if a != axis)))
    return np.mean(out, axis=0)


def save_profile(fig, bx, title: str, out: Path) -> Path:
    """Label the profile's axes ``bx``, title it, and write ``fig`` as out/wind_slice.png."""
    bx.set_xlabel("speed (m/s)")
    bx.set_ylabel("height y (m)")
    bx.set_title(title)
    bx.legend(fontsize=7, loc="lower right")
    return save_figure(fig, out / "wind_slice.png")


def physical_plots(args, plt) -> tuple[Path, Path]:
    """The default physical wind: spectra at fixed points over time, a slice and the profile."""
    from scipy.signal import welch

    wind = WindField(speed=args.speed, seed=args.seed)  # the default field, as the commands make it
    H, L, U = wind.canopy_height, wind.length_scale, wind.speed

    # -- spectra at fixed points at the canopy top, across the wind ---------------------------
    rate = args.rate
    n = max(int(round(args.seconds * rate)), 64)
    across = np.linspace(0.0, 6 * L, 24, endpoint=False)  # the tile is 6 L across the wind
    pts = np.column_stack([np.zeros_like(across), np.full_like(across, H), across])
    uvw = np.empty((n, len(pts), 3))
    for k in range(n):
        uvw[k] = wind.sample(pts, k / rate) @ wind.frame.T  # (along, vertical, lateral)
    f, psd = welch(uvw - uvw.mean(axis=0), fs=rate, nperseg=min(n, 1024), axis=0)
    psd = psd.mean(axis=1)  # (frequency, component), averaged over the points
    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    names = ("u (along wind)", "v (vertical)", "w (lateral)")
    betas = (wind.beta_u, wind.beta_vw, wind.beta_vw)
    scales = (L, L / 3, L / 3)
    colors = ("tab:blue", "tab:orange", "tab:green")
    top = U * 16 / (4 * L)  # half the tile's Nyquist frequency at a fixed point (16 cells per L)
    for i, (name, beta, lc, color) in enumerate(zip(names, betas, scales, colors)):
        f0 = U / (2 * np.pi * 1.339 * lc)
        band = (f >= 3 * f0) & (f <= top)
        spec = psd[1:, i] * 10.0 ** (-i)  # offset the curves so they do not overlap
        ff = f[1:]
        slope = np.polyfit(np.log(f[band]), np.log(psd[band, i]), 1)[0] if band.sum() > 2 else float("nan")
        ax.loglog(ff, spec, "-", lw=1, color=color, label=f"{name}: σ = {uvw[:, :, i].std():.2f} m/s, "
                                                          f"slope {slope:.2f} above {3 * f0:.2f} Hz")
        shape = (ff ** 2 + f0 ** 2) ** (-beta / 2)
        ref = shape * np.exp(np.mean(np.log(spec[band[1:]] / shape[band[1:]]))) if band.sum() else shape
        ax.loglog(ff, ref, "--", color=color, lw=1, label=f"von Kármán, β = {beta:.3g}, L_c = {lc:.3g} m")
    ax.axvline(top, color="0.6", lw=0.8)
    ax.set_xlabel("frequency f (Hz)")
    ax.set_ylabel("power spectral density (m²/s² per Hz; offset by decades)")
    ax.set_title(f"Physical wind at the canopy top: U = {U:g} m/s, L = {L:g} m, {n / rate:g} s")
    ax.legend(fontsize=6.5, loc="lower left")
    spectrum_png = save_figure(fig, args.out / "wind_spectrum.png")

    # -- a vertical slice along the wind, and the mean profile ---------------------------------
    xs = np.linspace(-2 * L, 2 * L, 200)
    ys = np.linspace(0.02 * H, 2 * H, 100)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)])
    u = wind.sample(pts, args.time)
    speed = np.linalg.norm(u, axis=1).reshape(gx.shape)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.8), dpi=120, gridspec_kw={"width_ratios": [2, 1]})
    im = ax.pcolormesh(gx, gy, speed, shading="auto", cmap="viridis")
    fig.colorbar(im, ax=ax, label="wind speed (m/s)")
    sx, sy = 12, 10
    ax.quiver(gx[::sy, ::sx], gy[::sy, ::sx], u[:, 0].reshape(gx.shape)[::sy, ::sx],
              u[:, 1].reshape(gx.shape)[::sy, ::sx], color="white", scale=30 * U, width=0.003)
    ax.axhline(H, color="white", lw=0.8, ls=":")
    ax.set_xlabel("x (m), wind along +x")
    ax.set_ylabel("height y (m)")
    ax.set_title(f"Wind speed on the plane z = 0, t = {args.time:g} s (dotted: canopy height)")
    ax.set_aspect("equal")

    heights = np.linspace(0.02 * H, 2 * H, 40)
    rng = np.random.default_rng(1)
    samples = []
    for t in np.linspace(0.0, 20 * L / U, 40):  # many eddies pass
        p = np.column_stack([np.repeat(rng.uniform(-4 * L, 4 * L, 40), len(heights)),
                             np.tile(heights, 40), np.repeat(rng.uniform(0, 6 * L, 40), len(heights))])
        samples.append((wind.sample(p, t) @ wind.frame[0]).reshape(40, len(heights)))
    along = np.concatenate(samples)
    bx.plot(along.mean(axis=0), heights, "o", ms=3, label="measured mean along-wind speed")
    bx.plot(U * wind.profile(heights), heights, "-", color="tab:red", label="U · canopy profile")
    bx.plot(along.std(axis=0), heights, "s", ms=3, color="tab:green", label="measured σ_u")
    bx.axhline(H, color="0.5", lw=0.8, ls=":")
    return spectrum_png, save_profile(fig, bx, "Mean profile", args.out)


def paper_plots(args, plt) -> tuple[Path, Path]:
    """The paper's field (Eqs. 13–18): its noise grids' spectra and a slice with the log profile."""
    wind = WindField(model="paper", speed=args.speed, grid=args.grid, seed=args.seed)
    n = wind.grid

    # -- spectra ---------------------------------------------------------------------------
    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    k = np.arange(1, n // 2 + 1)
    band = np.arange(2, max(n // 8, 3) + 1)
    names = ("u (along wind)", "v (vertical)", "w (lateral)")
    betas = (wind.beta_u, wind.beta_vw, wind.beta_vw)
    colors = ("tab:blue", "tab:orange", "tab:green")
    for i, (g, name, beta, color) in enumerate(zip(wind.grids, names, betas, colors)):
        spec = axis_spectrum(g)[1:]
        spec = spec * 10.0 ** (-i)  # offset the curves so they do not overlap
        slope = np.polyfit(np.log(band), np.log(spec[band - 1]), 1)[0]
        ax.loglog(k, spec, "o-", ms=3, color=color, label=f"{name}: fitted slope {slope:.2f}")
        ref = spec[band[0] - 1] * (k / band[0]) ** (-beta)
        ax.loglog(k, ref, "--", color=color, lw=1, label=f"k^−{beta:g}")
    ax.axvspan(band[0], band[-1], color="0.9", zorder=0, label="fit band k = 2 … N/8")
    ax.set_xlabel("wavenumber k (cycles per grid)")
    ax.set_ylabel("1-D power (curves offset by decades)")
    ax.set_title(f"Wind noise spectra, N = {n}")
    ax.legend(fontsize=7, loc="lower left")
    spectrum_png = save_figure(fig, args.out / "wind_spectrum.png")

    # -- vertical slice (Fig. 7b) ----------------------------------------------------------
    (x0, y0, z0), (x1, y1, z1) = wind.bounds
    xs = np.linspace(x0, x1, 160)
    ys = np.linspace(y0, y1, 160)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, 0.5 * (z0 + z1))])
    u = wind.sample(pts, args.time)
    speed = np.linalg.norm(u, axis=1).reshape(gx.shape)

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4.8), dpi=120,
                                 gridspec_kw={"width_ratios": [1.6, 1]})
    im = ax.pcolormesh(gx, gy, speed, shading="auto", cmap="viridis")
    fig.colorbar(im, ax=ax, label="wind speed (m/s)")
    step = 10
    ax.quiver(gx[::step, ::step], gy[::step, ::step],
              u[:, 0].reshape(gx.shape)[::step, ::step], u[:, 1].reshape(gx.shape)[::step, ::step],
              color="white", scale=25 * args.speed, width=0.003)
    ax.set_xlabel("x (m), wind along +x")
    ax.set_ylabel("height y (m)")
    ax.set_title(f"Wind speed on the plane z = {0.5 * (z0 + z1):g} m, t = {args.time:g} s")
    ax.set_aspect("equal")

    # mean speed per height over many x, z, times and 8 seeds (one seed's noise differs
    # from one height slice to the next) vs the log law
    heights = np.linspace(y0, y1, 50)
    rng = np.random.default_rng(1)
    mean = np.zeros(len(heights))
    seeds = [args.seed + i for i in range(8)]
    for seed in seeds:
        w = WindField(model="paper", speed=args.speed, grid=args.grid, seed=seed)
        for j, h in enumerate(heights):
            p = np.column_stack(
                [rng.uniform(x0, x1, 500), np.full(500, h), rng.uniform(z0, z1, 500)]
            )
            mean[j] += np.mean([np.linalg.norm(w.sample(p, t), axis=1).mean()
                                for t in np.linspace(0, 40, 6)])
    mean /= len(seeds)
    # Eq. 17 scales each sample by 1 + λ(s2/s1 − 0.5), whose mean is near but not exactly 1;
    # the log law is drawn at the nominal speed and least-squares scaled, to compare shapes.
    law = wind.profile(heights)
    fit = float(mean @ law / (law @ law))
    bx.plot(mean, heights, "o", ms=3, label=f"measured mean speed ({len(seeds)} seeds)")
    bx.plot(args.speed * law, heights, ":", color="0.4",
            label=f"speed·c1·ln(c2·h), c1 = {wind.c1:.3f}, c2 = {wind.c2:g}/m")
    bx.plot(fit * law, heights, "-", color="tab:red",
            label=f"c1·ln(c2·h) × {fit:.2f} m/s (least squares)")
    return spectrum_png, save_profile(fig, bx, "Mean profile (Eq. 16)", args.out)



def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out"), help="output directory")
    parser.add_argument("--paper", action="store_true",
                        help="plot the paper's field (Eqs. 13-18) instead of the default physical wind")
    parser.add_argument("--speed", type=float, default=5.0,
                        help="wind speed at the canopy top (paper: the top), m/s (default 5)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--time", type=float, default=0.0, help="time of the slice, s")
    parser.add_argument("--seconds", type=float, default=400.0,
                        help="physical: seconds of wind the spectra are measured over (default 400)")
    parser.add_argument("--rate", type=float, default=10.0, help="physical: samples per second (default 10)")
    parser.add_argument("--grid", type=int, default=64, help="paper: noise grid edge N (default 64)")
    args = parser.parse_args(argv)

    plt = pyplot()
    if plt is None:
        print(f"wind_spectrum.py {PLOTS_HINT}", file=sys.stderr)
        return 1

    args.out.mkdir(parents=True, exist_ok=True)
    spectrum_png, slice_png = (paper_plots if args.paper else physical_plots)(args, plt)
    which = "the paper's field" if args.paper else "the physical wind"
    print(f"wrote {spectrum_png} and {slice_png} ({which})")
    return 0

if __name__ == "__main__":
    sys.exit(main())
