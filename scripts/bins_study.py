#!/usr/bin/python3
"""The normal-aware table against plain and compensated balance MIS, exact, over a folder of maps.

Runs `envmis compare --exact` in library mode (one JSON per map) and prints, per BSDF, the
geometric mean over every map's points of the exact variance of `mis-balance-bins` and of
`mis-balance-comp` over `mis-balance`, the worst point of bins over `mis-balance` and over
the lower of `mis-balance` and `mis-balance-comp` at that point, and, per map, the same figures:
the "closer to the limit" and "never worse" figures of docs/performance.md. With them, the
efficiency of bins over the compensated table: (exact variance x ns/est) of
`mis-balance-comp` over that of `mis-balance-bins` (ns/est as compare times it, apart on one core:
docs/compare.md; --jobs 1, the default, so that no other map shares the cores).

    /usr/bin/python3 scripts/bins_study.py ../shared/data/envmaps --work /tmp/bins-study \
        [--envmis build/apps/envmis] [-- extra compare options, e.g. --view-angle 75]
"""
import argparse
import json
import math
import pathlib
import subprocess
import sys

BSDFS = "lambert,phong:20,phong:200,ggx:0.1"
TECHNIQUES = "mis-balance,mis-balance-comp,mis-balance-bins"


def run(args, extra):
    command = [args.envmis, "compare", args.maps, "--out-dir", args.work, "--exact", "--bins", "121",
               "--bsdf", args.bsdf, "--techniques", TECHNIQUES, "--points", str(args.points), "--spp", str(args.spp),
               "--jobs", str(args.jobs), "--force"] + extra
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)


def geomean(xs):
    return math.exp(sum(math.log(x) for x in xs) / len(xs))


def table(work, bsdfs):
    rows = {}
    for path in sorted(pathlib.Path(work).glob("*.json")):
        if path.name == "summary.json":
            continue
        result = json.loads(path.read_text())
        exact = result["exact"]
        ns = {(r["bsdf"], r["technique"]): r["ns_per_estimate"] for r in result["results"]}
        rows[path.stem] = {b: (exact[b]["mis-balance-bins"], exact[b]["mis-balance-comp"],
                               ns[b, "mis-balance-comp"] / ns[b, "mis-balance-bins"]) for b in bsdfs}
    if not rows:
        sys.exit(f"bins_study: no results in {work}")

    def over_lower(bins, comp):  # worst point of bins over min(mis-balance, mis-balance-comp)
        if "points" not in bins:  # written by a build before per-point ratios
            return math.nan
        return max(b / min(1.0, c) for b, c in zip(bins["points"], comp["points"]) if b > 0 and c > 0)

    def efficiency(bins, comp, speed):  # of bins over comp
        return comp["ratio"] / bins["ratio"] * speed

    print("| map | " + " | ".join(f"{b} bins/mis (worst; over the lower) · comp/mis · eff" for b in bsdfs) + " |")
    print("|---" * (len(bsdfs) + 1) + "|")
    for name, per in rows.items():
        cells = [f"{bins['ratio']:.3f} ({bins['worst']:.2f}; {over_lower(bins, comp):.2f}) · {comp['ratio']:.3f} · "
                 f"{efficiency(bins, comp, speed):.2f}" for bins, comp, speed in per.values()]
        print(f"| {name} | " + " | ".join(cells) + " |")
    every = [efficiency(*r[b]) for r in rows.values() for b in bsdfs]
    print(f"every map and BSDF: efficiency bins/comp geomean {geomean(every):.2f}, lowest {min(every):.2f}")
    for b in bsdfs:
        worst = max(rows, key=lambda m: rows[m][b][0]["worst"])
        lower = {m: over_lower(rows[m][b][0], rows[m][b][1]) for m in rows}
        worst_lower = max(lower, key=lower.get)
        bins = geomean([r[b][0]["ratio"] for r in rows.values()])
        comp = geomean([r[b][1]["ratio"] for r in rows.values()])
        eff = [efficiency(*r[b]) for r in rows.values()]
        print(f"{b}: bins/mis geomean {bins:.3f} (gain {1 / bins:.2f}x), worst {rows[worst][b][0]['worst']:.2f} "
              f"({worst}), over the lower of mis and comp {lower[worst_lower]:.2f} ({worst_lower}); "
              f"comp/mis {comp:.3f}; efficiency bins/comp geomean {geomean(eff):.2f}, lowest {min(eff):.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("maps", help="folder of HDR maps")
    parser.add_argument("--work", required=True, help="folder for the per-map JSON")
    parser.add_argument("--envmis", default="build/apps/envmis")
    parser.add_argument("--bsdf", default=BSDFS)
    parser.add_argument("--points", type=int, default=16)
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--from-json", action="store_true", help="summarise the JSON already in --work")
    args, extra = parser.parse_known_args()
    extra = [e for e in extra if e != "--"]
    if not args.from_json:
        run(args, extra)
    table(args.work, args.bsdf.split(","))


if __name__ == "__main__":
    main()
