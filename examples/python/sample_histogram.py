#!/usr/bin/env python3
"""Histogram of a map's samples against its pdf, over the image.

Draws N directions from an environment map (envmis.EnvMap.sample), counts them in a grid
of bins over the image (their image points uv), and sets the counts beside what the
sampling density predicts for each bin: the map's image-space density (q(x, y) w_y,
envmis.EnvMap.density) summed over the bin's texels, which is the map's solid-angle pdf
integrated over the bin's solid angle. Plots observed and expected fractions side by side
and their ratio, and prints a chi-square goodness-of-fit statistic per degree of freedom
(about 1 for a correct sampler: its standard deviation is sqrt(2 / dof)).

    sample_histogram.py data/envmaps/rooitou_park_1k.hdr -o histogram.png
"""

import argparse
import os
import sys

import numpy as np


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    parser.add_argument("map", help="HDR image (EXR, .hdr, ...) or envmis table file")
    parser.add_argument("-o", "--output", required=True, help="PNG to write")
    parser.add_argument("-n", "--samples", type=int, default=1_000_000, help="samples to draw (default 10^6)")
    parser.add_argument("--bins", default="64x32", help="histogram bins WxH over the image (default 64x32)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the uniform points (default 1)")
    parser.add_argument("--alpha", default="1",
                        help="compensation strength >= 0, 'auto', or 'none' for the plain luminance density "
                             "(default 1)")
    arguments = parser.parse_args(argv)
    try:
        width, height = (int(side) for side in arguments.bins.lower().split("x"))
    except ValueError:
        parser.error(f"--bins {arguments.bins!r}: expected WxH, e.g. 64x32")
    if width < 1 or height < 1:
        parser.error(f"--bins {arguments.bins!r}: each side must be at least 1")
    if arguments.samples < 1:
        parser.error(f"--samples {arguments.samples}: must be at least 1")
    arguments.bins = (height, width)
    return arguments


def load_map(envmis, path, alpha):
    if alpha == "none":
        return envmis.load(path, compensate=False)
    if alpha == "auto":
        return envmis.load(path, alpha="auto")
    return envmis.load(path, alpha=float(alpha))


def block_sums(image, bins):
    """Sums of `image` (H, W) over a grid of bins (rows, columns); texels are assigned to
    the bin that holds their centre, as np.histogram2d assigns image points."""
    rows, columns = bins
    height, width = image.shape
    row_bin = np.minimum(((np.arange(height) + 0.5) * rows / height).astype(int), rows - 1)
    column_bin = np.minimum(((np.arange(width) + 0.5) * columns / width).astype(int), columns - 1)
    by_row = np.zeros((rows, width))
    np.add.at(by_row, row_bin, image)
    sums = np.zeros((rows, columns))
    np.add.at(sums.T, column_bin, by_row.T)
    return sums


def chi_square(observed, expected, n):
    """Pearson's statistic over the bins expecting at least 5 samples (the others pooled
    into one bin), and its degrees of freedom."""
    counts = expected * n
    kept = counts >= 5
    o = np.append(observed[kept], observed[~kept].sum())
    e = np.append(counts[kept], counts[~kept].sum())
    used = e > 0
    statistic = float(np.sum((o[used] - e[used]) ** 2 / e[used]))
    return statistic, int(used.sum()) - 1


def plot(path, title, observed_fraction, expected, ratio):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from matplotlib.colors import LogNorm

    figure, axes = plt.subplots(1, 3, figsize=(15, 3.6), constrained_layout=True)
    # A log scale: a sun holds most of the probability, the sky the rest.
    top = max(observed_fraction.max(), expected.max())
    norm = LogNorm(vmin=top * 1e-6, vmax=top)
    extent = (0, 1, 1, 0)
    for ax, image, name in ((axes[0], observed_fraction, "samples (fraction per bin)"),
                            (axes[1], expected, "pdf integrated over each bin")):
        shown = ax.imshow(np.maximum(image, top * 1e-6), norm=norm, cmap="magma", aspect="auto", extent=extent)
        ax.set_title(name)
        figure.colorbar(shown, ax=ax)
    shown = axes[2].imshow(ratio, vmin=0.8, vmax=1.2, cmap="coolwarm", aspect="auto", extent=extent)
    axes[2].set_title("samples / pdf (bins expecting >= 100 samples)")
    figure.colorbar(shown, ax=axes[2])
    for ax in axes:
        ax.set_xlabel("image u")
        ax.set_ylabel("image v")
    figure.suptitle(title)
    figure.savefig(path, dpi=80)


def main(argv):
    arguments = parse_arguments(argv)
    import envmis

    try:
        env = load_map(envmis, arguments.map, arguments.alpha)
    except (OSError, ValueError) as error:
        sys.exit(f"sample_histogram.py: {error}")
    u = np.random.default_rng(arguments.seed).random((arguments.samples, 2), dtype=np.float32)
    samples = env.sample(u)
    drawn = samples.pdf > 0
    n = int(drawn.sum())
    rows, columns = arguments.bins
    observed, _, _ = np.histogram2d(samples.uv[drawn, 1], samples.uv[drawn, 0], bins=(rows, columns),
                                    range=((0, 1), (0, 1)))
    density = np.asarray(env.density, dtype=np.float64)
    expected = block_sums(density, arguments.bins) / density.sum()
    statistic, dof = chi_square(observed, expected, n)
    counts = expected * n
    ratio = np.where(counts >= 100, observed / np.maximum(counts, 1e-300), np.nan)
    print(f"{arguments.map}: {n} samples in {columns}x{rows} bins; chi-square {statistic:.1f} over {dof} "
          f"degrees of freedom: {statistic / max(dof, 1):.3f} per degree (1 expected, +-{np.sqrt(2 / max(dof, 1)):.3f}); "
          f"samples / pdf in [{np.nanmin(ratio):.3f}, {np.nanmax(ratio):.3f}] over the bins expecting >= 100")
    name = os.path.basename(arguments.map)
    plot(arguments.output, f"{name}: {n} samples against the pdf", observed / n, expected, ratio)
    print(f"wrote {arguments.output}")


if __name__ == "__main__":
    main(sys.argv[1:])
