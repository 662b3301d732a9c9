#!/usr/bin/python3
"""Relative MSE of two techniques' sphere renders, per sphere and per 16x16 block.

Reads the EXRs that `envmis compare MAP --images DIR --techniques A,B ...` writes (A.exr,
B.exr, reference.exr: one sphere per BSDF, side by side) and prints, per sphere, the
relative MSE of each (mean over the sphere's pixels of (x - ref)^2 / (ref^2 + 1e-4), on
luminance, pixels whose reference is above 0), their ratio B/A, the worst 16x16 block's
ratio and how many blocks B has worse. The render check of docs/performance.md.

    /usr/bin/python3 scripts/sphere_blocks.py DIR mis-balance-comp mis-balance-bins [--spheres N]
"""
import argparse
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "build" / "python"))
import envmis  # noqa: E402

LUMA = np.array([0.2126, 0.7152, 0.0722])
BLOCK = 16


def luminance(path):
    return envmis.load(str(path), compensate=False).radiance @ LUMA


def rel_se(x, ref):
    return (x - ref) ** 2 / (ref ** 2 + 1e-4)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder")
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--spheres", type=int, help="spheres in the row (default: width / height)")
    args = parser.parse_args()
    folder = pathlib.Path(args.folder)
    ref = luminance(folder / "reference.exr")
    a, b = (rel_se(luminance(folder / f"{t}.exr"), ref) for t in (args.a, args.b))
    h, w = ref.shape
    spheres = args.spheres or max(1, w // h)
    side = w // spheres
    for s in range(spheres):
        cols = slice(s * side, (s + 1) * side)
        lit = ref[:, cols] > 0
        ea, eb = a[:, cols][lit].mean(), b[:, cols][lit].mean()
        worst, where, worse, blocks = 0.0, (0, 0), 0, 0
        for y in range(0, h - BLOCK + 1, BLOCK):
            for x in range(s * side, (s + 1) * side - BLOCK + 1, BLOCK):
                mask = ref[y:y + BLOCK, x:x + BLOCK] > 0
                if mask.sum() < BLOCK * BLOCK // 4:
                    continue
                ba, bb = a[y:y + BLOCK, x:x + BLOCK][mask].mean(), b[y:y + BLOCK, x:x + BLOCK][mask].mean()
                if not ba > 0:
                    continue
                blocks += 1
                worse += bb > ba
                if bb / ba > worst:
                    worst, where = bb / ba, (x, y)
        print(f"sphere {s}: relMSE {args.a} {ea:.5g} {args.b} {eb:.5g} (B/A {eb / ea:.3f}); worst block B/A "
              f"{worst:.2f} at {where[0]},{where[1]}; blocks with B worse {worse} of {blocks}")


if __name__ == "__main__":
    main()
