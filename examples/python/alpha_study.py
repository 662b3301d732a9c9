#!/usr/bin/env python3
"""Variance of compensated MIS against the compensation strength, per BSDF and map.

For each map, the variance of ONE mis-balance-comp estimate (balance-heuristic MIS of
BSDF sampling with the map's MIS-compensated density, Karlik et al. 2019) relative to
ONE mis-balance estimate (the same with the plain luminance density), as a function of
the compensation strength alpha: exact variances (quadrature, no noise; the criterion of
envmis.choose_alpha, on a copy of the map downsampled to --max-width texels), the
geometric mean over shading points spread over the sphere. Below 1, compensation lowers
the variance. One line per BSDF, one panel per map; each BSDF's best alpha is marked.
With --measured SPP, the ratio envmis.compare measures with SPP estimates per point is
drawn as dots at every alpha too.

    alpha_study.py data/envmaps/*.hdr data/envmaps/*.exr -o alpha_study.png
"""

import argparse
import math
import os
import sys

import numpy as np


def alphas_of(text):
    """'0:3:0.25' (first, last, step) or '0,0.5,1' as a sorted list of floats >= 0."""
    try:
        if ":" in text:
            first, last, step = (float(v) for v in text.split(":"))
            if not (step > 0 and last >= first):
                raise ValueError
            values = list(np.arange(first, last + step / 2, step))
        else:
            values = [float(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected A0:A1:STEP or a comma-separated list")
    if not values or not all(math.isfinite(v) and v >= 0 for v in values):
        raise argparse.ArgumentTypeError(f"{text!r}: every alpha must be a finite number >= 0")
    return sorted(set(round(v, 6) for v in values))


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n\n", 1)[1])
    parser.add_argument("maps", nargs="+", metavar="MAP", help="HDR images (EXR, .hdr, ...) or envmis table files")
    parser.add_argument("-o", "--output", required=True, help="PNG to write")
    parser.add_argument("--bsdfs", default="lambert,phong:50,ggx:0.1",
                        help="BSDFs, comma-separated, as envmis compare --bsdf (default lambert,phong:50,ggx:0.1)")
    parser.add_argument("--alphas", type=alphas_of, default=alphas_of("0:3:0.25"),
                        help="compensation strengths: A0:A1:STEP or a list (default 0:3:0.25)")
    parser.add_argument("--points", type=int, default=16, help="shading points over the sphere (default 16)")
    parser.add_argument("--max-width", type=int, default=128,
                        help="width of the downsampled copy the exact variances run on (default 128)")
    parser.add_argument("--measured", type=int, default=0, metavar="SPP",
                        help="also measure the ratio with envmis.compare, SPP estimates per point (default: off)")
    arguments = parser.parse_args(argv)
    if arguments.points < 1 or arguments.max_width < 1 or arguments.measured < 0:
        parser.error("--points and --max-width must be at least 1, --measured at least 0")
    return arguments


def study(envmis, path, arguments):
    """(name, exact ratios {bsdf: [per alpha]}, best alphas {bsdf: alpha}, measured {bsdf: [per alpha]})."""
    env = envmis.load(path, compensate=False)
    choice = envmis.choose_alpha(env, bsdfs=arguments.bsdfs, points=arguments.points,
                                 candidates=arguments.alphas, max_width=arguments.max_width)
    alphas = [c["alpha"] for c in choice["candidates"]]
    bsdfs = list(choice["bsdf_alphas"])
    exact = {b: [c["per_bsdf"][b] for c in choice["candidates"]] for b in bsdfs}
    measured = {}
    if arguments.measured:
        for alpha in alphas:
            comparison = envmis.compare(env, bsdfs=arguments.bsdfs, techniques=["mis-balance", "mis-balance-comp"],
                                        spp=arguments.measured, points=arguments.points, alpha=alpha)
            for record in comparison.records:
                if record["technique"] == "mis-balance-comp":
                    measured.setdefault(record["bsdf"], []).append(record["variance_ratio_vs_mis"])
    return os.path.basename(path), alphas, exact, choice["bsdf_alphas"], measured


def plot(path, results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    columns = min(3, len(results))
    rows = math.ceil(len(results) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(5 * columns, 3.8 * rows), squeeze=False,
                                constrained_layout=True)
    for ax, (name, alphas, exact, best, measured) in zip(axes.flat, results):
        for index, (bsdf, ratios) in enumerate(exact.items()):
            colour = f"C{index}"
            ax.plot(alphas, ratios, color=colour, label=f"{bsdf} (best alpha {best[bsdf]:g})")
            ax.plot([best[bsdf]], [ratios[alphas.index(best[bsdf])]], "o", color=colour, markerfacecolor="none")
            if bsdf in measured:
                ax.plot(alphas, measured[bsdf], ".", color=colour)
        ax.axhline(1, color="grey", linewidth=0.8)
        ax.set_title(name)
        ax.set_xlabel("compensation strength alpha")
        ax.set_ylabel("variance / variance of mis-balance")
        ax.legend(fontsize="small")
    for ax in list(axes.flat)[len(results):]:
        ax.set_visible(False)
    figure.savefig(path, dpi=80)


def main(argv):
    arguments = parse_arguments(argv)
    import envmis

    results = []
    for path in arguments.maps:
        try:
            results.append(study(envmis, path, arguments))
        except (OSError, ValueError) as error:
            sys.exit(f"alpha_study.py: {error}")
        name, alphas, exact, best, _ = results[-1]
        print(f"{name}: " + ", ".join(f"{b} best alpha {best[b]:g} ({min(exact[b]):.3f}x mis-balance)"
                                      for b in exact))
    plot(arguments.output, results)
    print(f"wrote {arguments.output}")


if __name__ == "__main__":
    main(sys.argv[1:])
