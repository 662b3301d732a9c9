#!/usr/bin/python3
"""What envmis gives a path tracer at equal samples and at equal time.

For each map and scene: the map is converted to pbrt-v4's equal-area square (so that
every technique, the pbrt-v4-style reference sampler included, samples the same
texels), three tables are built from it (plain, compensated, normal-aware with 121 bins),
a high-spp reference is rendered with the plain table, then every technique renders the
scene with several seeds at equal samples and at equal time (the time the compensated table
took for those samples, the budget each technique gets), the techniques interleaved. The
relative MSE against the reference (envmis_example_pathtrace --reference) is averaged over
seeds; the table gives it with the ratio of the global compensated table's (and the
pbrt-v4-style sampler's) to the normal-aware table's: above 1, bins have the lower error.

Usage (after building envmis and the examples against an install; docs/results-renderer.md):
  /usr/bin/python3 scripts/renderer_compare.py --envmis build/apps/envmis \
      --renderer build-examples/envmis_example_pathtrace --work /tmp/rc \
      --json docs/results-renderer.json --markdown docs/results-renderer.md
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

TECHNIQUES = {  # name: (table, --env, more options: tables named by kind in braces)
    "plain": ("plain", "global", []),
    "compensated": ("compensated", "global", []),
    "pbrt": ("compensated", "pbrt", []),
    "bins": ("bins", "bins", []),
    # Bins at the camera's hit only, the compensated table at every later vertex.
    "bins-first": ("bins", "bins", ["--bins-depth", "1", "--beyond", "{compensated}"]),
}
FLOOR_LIGHT_SAMPLES = 32
REPO = Path(__file__).resolve().parent.parent


def run(command, quiet=True):
    result = subprocess.run([str(c) for c in command], capture_output=quiet, text=True)
    if result.returncode != 0:
        sys.exit(f"renderer_compare: failed ({result.returncode}): {' '.join(map(str, command))}\n"
                 f"{result.stderr if quiet else ''}")
    return result


def tables(envmis, work, map_path):
    """The equal-area square of the map and its three tables (made once, kept in work/)."""
    stem = Path(map_path).stem
    square = work / f"{stem}.square.exr"
    if not square.exists():
        run([envmis, "convert", map_path, "-o", square])
    options = {"plain": ["--no-compensate"], "compensated": [], "bins": ["--bins", "121"]}
    made = {}
    for name, extra in options.items():
        table = work / f"{stem}.{name}.envmis"
        if not table.exists():
            run([envmis, "precompute", square, "-o", table, "--mapping", "equal-area", *extra])
        made[name] = table
    return made


def render(args, table, env, scene, out, seed, bounces, spp=None, seconds=None, reference=None, light_samples=1,
           profile=False, more=()):
    command = [args.renderer, table, "-o", out, "--scene", scene, "--env", env, "--size", args.size,
               "--seed", seed, "--bounces", bounces, "--threads", args.threads, "--light-samples", light_samples,
               *more]
    command += ["--spp", spp] if spp else []
    command += ["--time", f"{seconds:.4f}"] if seconds else []
    command += ["--reference", reference] if reference else []
    command += ["--profile"] if profile else []
    run(command)
    result = json.loads(Path(out).with_suffix(".json").read_text())
    if reference and result["relative_mse"] is None:  # the renderer writes null for a NaN
        sys.exit(f"renderer_compare: {out}: relative MSE is not finite (NaN pixels?)")
    return result


def interleaved(seeds, names):
    """(seed, technique) in the order the renders run: every technique once per seed, the
    order turned by one each seed, so that the machine's speed, which drifts within
    minutes on a shared host, weighs on every technique alike rather than on whichever
    ran its seeds in a slow spell."""
    names = list(names)
    for k, s in enumerate(seeds):
        turn = k % len(names)
        for name in names[turn:] + names[:turn]:
            yield s, name


def compare_case(args, made, scene, stem, work, bounces):
    """One scene under one map: reference, then each technique at equal spp and equal time
    (interleaved), the sampler's share profiled in a run of its own (profiling costs time),
    and the floor: the plain (complete) table with FLOOR_LIGHT_SAMPLES environment samples
    a vertex."""
    prefix = work / f"{stem}.{scene}.b{bounces}"
    # Named by what makes it, so that a run with another size or count renders its own.
    reference = Path(f"{prefix}.reference.{args.size}.{args.reference_spp}spp.exr")
    if not reference.exists():
        render(args, made["plain"], "global", scene, reference, 1000, bounces, spp=args.reference_spp)
    case = {"scene": scene, "map": stem, "techniques": {}}
    seeds = range(1, args.seeds + 1)
    more = {name: [m.format(**{k: str(v) for k, v in made.items()}) for m in extra]
            for name, (_, _, extra) in TECHNIQUES.items()}

    def renders(mode, **kwargs):
        done = {name: [] for name in TECHNIQUES}
        for s, name in interleaved(seeds, TECHNIQUES):
            table, env, _ = TECHNIQUES[name]
            done[name].append(render(args, made[table], env, scene, f"{prefix}.{name}.{mode}.{s}.exr", s, bounces,
                                     reference=reference, more=more[name], **kwargs))
        return done

    runs = renders("spp", spp=args.spp)
    budget = statistics.median(r["seconds"] for r in runs["compensated"])
    timed = renders("time", seconds=budget)
    for name, (table, env, _) in TECHNIQUES.items():
        profiled = render(args, made[table], env, scene, f"{prefix}.{name}.profile.exr", 1, bounces, spp=args.spp,
                          profile=True, more=more[name])
        equal_spp = runs[name]
        case["techniques"][name] = {
            "equal_spp_relative_mse": statistics.mean(r["relative_mse"] for r in equal_spp),
            "equal_spp_seconds": statistics.median(r["seconds"] for r in equal_spp),
            "equal_time_relative_mse": statistics.mean(r["relative_mse"] for r in timed[name]),
            "equal_time_passes": statistics.median(r["passes"] for r in timed[name]),
            "rays_per_second_per_thread": statistics.median(r["rays_per_second_per_thread"] for r in equal_spp),
            "sampler_share": profiled["sampler_share"],
            "sampler_ns_per_vertex": sampler_ns_per_vertex(profiled),
            "per_seed": {"equal_spp": [r["relative_mse"] for r in equal_spp],
                         "equal_time": [r["relative_mse"] for r in timed[name]]},
        }
    floor = [render(args, made["plain"], "global", scene, f"{prefix}.floor.{s}.exr", s, bounces, spp=args.spp,
                    reference=reference, light_samples=FLOOR_LIGHT_SAMPLES) for s in seeds]
    case["floor_relative_mse"] = statistics.mean(r["relative_mse"] for r in floor)
    case["budget_seconds"] = budget
    case["triangles"] = runs["plain"][0]["triangles"]
    case["cpu"] = runs["plain"][0]["cpu"]
    return case


def sampler_ns_per_vertex(profiled):
    """The environment's time at a path vertex (choosing the bin, the light samples and
    the lookup of an escaping material sample), from a profiled render's share of the
    threads' time: what a sampler costs where a renderer's traversal has evicted it."""
    vertices = profiled["environment_samples"] / profiled["light_samples"]
    return profiled["sampler_share"] * profiled["thread_seconds"] / vertices * 1e9 if vertices else 0.0


def ratio(case, over, mode, of="bins"):
    """relMSE of `over` over `of`'s: at equal spp, at equal time (each given the budget), or
    by cost ("cost": relMSE x seconds at equal spp, the equal-time ratio without the
    budget's whole-pass rounding)."""
    t = case["techniques"]
    if mode == "cost":
        return (t[over]["equal_spp_relative_mse"] * t[over]["equal_spp_seconds"]) / (
            t[of]["equal_spp_relative_mse"] * t[of]["equal_spp_seconds"])
    return t[over][f"{mode}_relative_mse"] / t[of][f"{mode}_relative_mse"]


def share(technique):
    ns = technique.get("sampler_ns_per_vertex")  # absent from runs before it was recorded
    return f"{technique['sampler_share']:.0%}" + (f" ({ns:.0f})" if ns else "")


def table_lines(cases):
    lines = [
        "| scene | map | comp/bins: equal spp · equal time · by cost | pbrt/bins: equal time · by cost | "
        "plain/bins, equal time | comp/bins-first: equal time · by cost | floor/comp | "
        "passes bins / comp / pbrt | sampler share (ns a vertex) bins / comp / pbrt | Mrays/s/thread |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for c in cases:
        t = c["techniques"]
        lines.append(
            f"| {c['scene']} | {c['map']} | {ratio(c, 'compensated', 'equal_spp'):.2f} · "
            f"{ratio(c, 'compensated', 'equal_time'):.2f} · {ratio(c, 'compensated', 'cost'):.2f} | "
            f"{ratio(c, 'pbrt', 'equal_time'):.2f} · {ratio(c, 'pbrt', 'cost'):.2f} | "
            f"{ratio(c, 'plain', 'equal_time'):.2f} | "
            f"{ratio(c, 'compensated', 'equal_time', 'bins-first'):.2f} · "
            f"{ratio(c, 'compensated', 'cost', 'bins-first'):.2f} | "
            f"{c['floor_relative_mse'] / t['compensated']['equal_spp_relative_mse']:.2f} | "
            f"{t['bins']['equal_time_passes']:g} / {t['compensated']['equal_time_passes']:g} / "
            f"{t['pbrt']['equal_time_passes']:g} | "
            f"{share(t['bins'])} / {share(t['compensated'])} / {share(t['pbrt'])} | "
            f"{t['compensated']['rays_per_second_per_thread'] / 1e6:.2f} |")
    lines += ["", "Relative MSE per technique (mean over seeds), equal samples / equal time:", "",
              "| scene | map | " + " | ".join(TECHNIQUES) + " |", "|---|---|" + "---|" * len(TECHNIQUES)]
    for c in cases:
        t = c["techniques"]
        cells = [f"{t[n]['equal_spp_relative_mse']:.4g} / {t[n]['equal_time_relative_mse']:.4g}" for n in TECHNIQUES]
        lines.append(f"| {c['scene']} | {c['map']} | " + " | ".join(cells) + " |")
    return lines


def markdown(results, args, command):
    cpu = results["runs"][0]["cases"][0]["cpu"]
    lines = [
        "# envmis in a path tracer: error at equal samples and at equal time",
        "",
        "Generated by `scripts/renderer_compare.py` (do not edit by hand). Command:",
        "",
        f"    {command}",
        "",
        f"CPU: {cpu}, {args.threads} threads. Images {args.size}; at every vertex one environment sample "
        f"(next-event estimation, shadow ray) and one material sample, balance heuristic; {args.spp} spp at "
        f"equal samples, {args.seeds} seeds; equal time: the time the compensated table took for {args.spp} spp, "
        f"for every technique; reference {args.reference_spp} spp (plain table, another seed). Relative MSE: "
        "mean over pixels of (Y - Y_ref)^2 / (Y_ref^2 + 0.01), averaged over seeds. Maps converted to the "
        "equal-area square (pbrt-v4's), so every technique samples the same texels. Scenes: "
        "apps/examples/pathtrace/scene.h.",
        "",
        "Columns: the other technique's relative MSE over the normal-aware table's (`bins`, 121 bins, at every "
        "vertex; `bins-first`: at the camera's hit only, the compensated table beyond): above 1, "
        "bins have the lower error. At equal time each technique renders for the budget (whole passes); "
        "`by cost` is the equal-time ratio from the equal-spp renders, relMSE x seconds, free of the "
        "passes' rounding. The renders run interleaved (each seed renders every technique, in an order "
        "turned by one each seed), so that the machine's drifting speed weighs on every technique alike. "
        f"`floor/comp`: the plain table with {FLOOR_LIGHT_SAMPLES} environment "
        "samples a vertex over the compensated table with one, at equal samples: the error left when direct light from the map is "
        "nearly noise-free, so 1 / floor is the most any environment sampler can gain at equal samples. "
        "Sampler share: the threads' time in the environment's calls (choosing the bin, sampling, looking up; "
        "timed with the CPU's cycle counter in a run of its own), and that time per path vertex in ns.",
    ]
    for run in results["runs"]:
        title = "Direct lighting only (1 bounce)" if run["bounces"] == 1 else f"Path tracing, {run['bounces']} bounces"
        lines += ["", f"## {title}", ""] + table_lines(run["cases"])
    return "\n".join(lines) + "\n"


def picture(results, args, path):
    """The README's comparison: one scene and map at equal time (seed 1), each technique
    beside the reference, labelled with its passes and relative MSE (matplotlib, from the
    renders' tone-mapped PNGs)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scene, map_stem = args.picture_case.split(":")
    run_ = next(r for r in results["runs"] if r["bounces"] == args.bounces[0])
    case = next((c for c in run_["cases"] if c["scene"] == scene and c["map"] == map_stem), None)
    if case is None:
        sys.exit(f"renderer_compare: no case {args.picture_case} in the results")
    prefix = Path(args.work) / f"{map_stem}.{scene}.b{run_['bounces']}"
    reference = f"{prefix}.reference.{args.size}.{args.reference_spp}spp.png"
    panels = [("reference", reference, f"{args.reference_spp} spp, plain table")]
    names = {"compensated": "global compensated", "pbrt": "pbrt-v4-style", "bins": "normal-aware (bins)"}
    for name, label in names.items():
        t = case["techniques"][name]
        json_path = Path(f"{prefix}.{name}.time.1.json")
        passes = json.loads(json_path.read_text())["passes"] if json_path.exists() else t["equal_time_passes"]
        panels.append((label, f"{prefix}.{name}.time.1.png",
                       f"{passes} spp, relMSE {t['equal_time_relative_mse']:.4f} (mean of {args.seeds} seeds)"))
    fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.1), dpi=100, layout="constrained")
    for ax, (title, png, detail) in zip(axes, panels):
        ax.imshow(plt.imread(png), interpolation="nearest")
        ax.set_title(f"{title}\n{detail}", fontsize=9)
        ax.set_axis_off()
    fig.suptitle(f"{scene} under {map_stem}, {run_['bounces']} bounces, equal time "
                 f"({case['budget_seconds']:.2f} s each, {case['cpu'].split(' (')[0]})", fontsize=10)
    # JPEG: noise, which is what the picture shows, makes PNGs large.
    fig.savefig(path, **({"pil_kwargs": {"quality": 90}} if str(path).endswith((".jpg", ".jpeg")) else {}))
    plt.close(fig)


def render_all(args, work):
    start = time.time()
    results = {"runs": [{"bounces": b, "cases": []} for b in args.bounces]}
    for map_path in args.maps:
        made = tables(args.envmis, work, map_path)
        for run_ in results["runs"]:
            for scene in args.scenes:
                case = compare_case(args, made, scene, Path(map_path).stem, work, run_["bounces"])
                run_["cases"].append(case)
                print(f"{run_['bounces']} bounces {scene:10s} {case['map']:16s} comp/bins "
                      f"{ratio(case, 'compensated', 'equal_spp'):5.2f} (spp) "
                      f"{ratio(case, 'compensated', 'equal_time'):5.2f} (time) "
                      f"{ratio(case, 'compensated', 'cost'):5.2f} (cost), pbrt/bins "
                      f"{ratio(case, 'pbrt', 'equal_time'):5.2f} (time)  [{time.time() - start:.0f} s]", flush=True)
    return results


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--envmis", required=True, help="the envmis command")
    p.add_argument("--renderer", required=True, help="envmis_example_pathtrace")
    p.add_argument("--work", required=True, help="folder for tables and images (reused: delete it to start over)")
    p.add_argument("--maps", nargs="+", default=[str(REPO / "data/envmaps" / m)
                                                  for m in ("rooitou_park_1k.hdr", "city.exr", "studio.exr")])
    p.add_argument("--scenes", nargs="+", default=["objects", "materials", "interior", "mesh"])
    p.add_argument("--size", default="160x120")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--reference-spp", type=int, default=1024)
    p.add_argument("--seeds", type=int, default=5)
    p.add_argument("--bounces", type=int, nargs="+", default=[4, 1], help="one table for each")
    p.add_argument("--threads", type=int, default=len(os.sched_getaffinity(0)), help="default: the usable cores")
    p.add_argument("--json", help="write the results here")
    p.add_argument("--markdown", help="write the tables here")
    p.add_argument("--picture", help="write a labelled equal-time comparison of --picture-case here (.jpg, .png)")
    p.add_argument("--picture-case", default="objects:studio", help="SCENE:MAP (the map's file stem)")
    p.add_argument("--from-json", help="skip rendering: the tables and picture from an earlier run's --json "
                                       "(its images still in --work)")
    args = p.parse_args()
    if args.spp < 1 or args.reference_spp < 2 or args.seeds < 1 or min(args.bounces) < 1 or args.threads < 1:
        p.error("--spp, --seeds, --bounces and --threads must be at least 1, --reference-spp at least 2")
    stems = [Path(m).stem for m in args.maps]
    if len(set(stems)) != len(stems):
        p.error("--maps: two maps share a file stem, which names their tables and images in --work")
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    command = "/usr/bin/python3 scripts/renderer_compare.py " + " ".join(sys.argv[1:])
    settings = {k: getattr(args, k) for k in ("size", "spp", "reference_spp", "seeds", "threads")}
    if args.from_json:
        results = json.loads(Path(args.from_json).read_text())
        results.setdefault("settings", dict(settings, command=command))
    else:
        results = render_all(args, work)
        results["settings"] = dict(settings, command=command)
    for k, v in results["settings"].items():
        setattr(args, k, v)
    args.bounces = [r["bounces"] for r in results["runs"]]
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1) + "\n")
    if args.markdown:
        Path(args.markdown).write_text(markdown(results, args, args.command))
    if args.picture:
        picture(results, args, args.picture)


if __name__ == "__main__":
    main()
