#!/usr/bin/python3
"""Checks that a render converges to the reference: the mean luminance of the image
(envmis_example_pathtrace's OUT.json, with its standard error over passes) within
`--sigmas` combined standard errors of the reference's.

Usage: check_mean.py REFERENCE.json IMAGE.json [--sigmas 4] [--differ]
With --differ, the opposite: the two means must be more than `--sigmas` apart (a change
that must show, such as a turned sky).
"""
import argparse
import json
import math
import sys

p = argparse.ArgumentParser()
p.add_argument("reference")
p.add_argument("image")
p.add_argument("--sigmas", type=float, default=4)
p.add_argument("--differ", action="store_true")
args = p.parse_args()
ref, img = (json.load(open(f)) for f in (args.reference, args.image))
if ref["passes"] < 2 or img["passes"] < 2:
    sys.exit("check_mean: each render needs 2 passes or more for a standard error")
difference = img["mean_luminance"] - ref["mean_luminance"]
error = math.hypot(img["standard_error"], ref["standard_error"])
print(f"{img['technique']} {img['scene']}: mean {img['mean_luminance']:.6g} +- {img['standard_error']:.2g}, "
      f"reference {ref['mean_luminance']:.6g} +- {ref['standard_error']:.2g}: {difference / error:+.2f} sigma")
if args.differ and not abs(difference) > args.sigmas * error:
    sys.exit(f"FAIL: within {args.sigmas} standard errors, expected apart")
if not args.differ and not abs(difference) <= args.sigmas * error:
    sys.exit(f"FAIL: more than {args.sigmas} standard errors apart")
