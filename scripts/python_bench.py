#!/usr/bin/python3
"""The cost of sampling from Python against the C++ batch call, in one process.

For each map: ns/sample of EnvMap.sample(u) at N points (u from envmis.uniform_points),
with new output arrays each call and with out= an earlier call's, and of the core's sample_many on
the same map and points (one array per coordinate, image points included; outputs
allocated in each call, or once), timed inside C++ by envmis._maps._time_sample_many;
medians over --repeats runs each, interleaved so that all see the same machine load. Run with the package on
the path:

    PYTHONPATH=build/python /usr/bin/python3 scripts/python_bench.py
"""

import argparse
import os
import pathlib
import statistics
import time

import numpy as np

import envmis


def synthetic(width, height, seed=1):
    """A sky with a sun: a few decades of dynamic range, one bright spot."""
    rng = np.random.default_rng(seed)
    radiance = rng.lognormal(0.0, 1.0, size=(height, width, 3)).astype(np.float32)
    radiance[height // 5 : height // 5 + 4, width // 3 : width // 3 + 4] = 1e4
    return envmis.EnvMap(radiance)


def measure(env, n, repeats):
    u = envmis.uniform_points(n, seed=1)
    out = env.sample(u)  # also warms the map's pages
    fresh, reused, cpp_fresh, cpp = [], [], [], []
    for _ in range(repeats):
        start = time.perf_counter()
        env.sample(u)
        fresh.append(time.perf_counter() - start)
        start = time.perf_counter()
        env.sample(u, out=out)
        reused.append(time.perf_counter() - start)
        cpp_fresh.append(envmis._maps._time_sample_many(env, u, 1, fresh_outputs=True))
        cpp.append(envmis._maps._time_sample_many(env, u, 1))
    return [statistics.median(t) * 1e9 / n for t in (fresh, cpp_fresh, reused, cpp)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=1_000_000, help="points per call")
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--large", action="store_true", help="also a 4096x2048 synthetic map")
    args = parser.parse_args()
    source = pathlib.Path(os.environ.get("ENVMIS_SOURCE_DIR", pathlib.Path(__file__).parents[1]))
    maps = [("rooitou_park_1k.hdr", envmis.load(source / "data" / "envmaps" / "rooitou_park_1k.hdr"))]
    if args.large:
        maps.append(("synthetic 4096x2048", synthetic(4096, 2048)))
    print(f"N = {args.n}, median of {args.repeats}")
    print("ns/sample; new outputs: Python's new arrays against C++ outputs allocated in the call;")
    print("reused: Python's out= against C++ outputs allocated once; ratio = Python / C++")
    print(f"{'map':22} {'new: Python':>12} {'C++':>8} {'ratio':>6} {'reused: Python':>15} {'C++':>8} {'ratio':>6}")
    for name, env in maps:
        fresh, cpp_fresh, reused, cpp = measure(env, args.n, args.repeats)
        print(f"{name:22} {fresh:12.2f} {cpp_fresh:8.2f} {fresh / cpp_fresh:6.3f} {reused:15.2f} {cpp:8.2f} {reused / cpp:6.3f}")


if __name__ == "__main__":
    main()
