"""envmis._maps: maps, tables and vectorised sampling from NumPy, held to the properties
the C++ tests check (tests/core/sampling, tests/core/table): sample and pdf agree, the
samples follow the density (chi-square), the pdf integrates to one, results are
bit-identical to the command line for the same seeds, tables round-trip, bad input
raises with the command's messages, and the views copy nothing."""

import ast
import gc
import json
import math
import os
import pathlib
import subprocess
import weakref

import numpy as np
import pytest

import envmis

SOURCE = pathlib.Path(os.environ.get("ENVMIS_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
PARK = SOURCE / "data" / "envmaps" / "rooitou_park_1k.hdr"
CLI = os.environ.get("ENVMIS_CLI", "")
REC709 = np.array([0.2126, 0.7152, 0.0722])


def random_radiance(width, height, seed, sun=True):
    """A map with a few decades of dynamic range and a bright texel (a sun)."""
    rng = np.random.default_rng(seed)
    radiance = rng.lognormal(0.0, 1.5, size=(height, width, 3)).astype(np.float32)
    if sun:
        radiance[height // 4, width // 3] = 500.0
    return radiance


def bits(array):
    return np.ascontiguousarray(array, dtype=np.float32).view(np.uint32)


def run_cli(*args):
    env = dict(os.environ, OCIO=str(SOURCE / "data" / "ocio" / "config.ocio"))
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, env=env, timeout=120)


needs_cli = pytest.mark.skipif(not CLI, reason="the envmis command was not built")


def wilson_hilferty(dof, z):
    """The chi-square quantile of `dof` degrees of freedom at the normal quantile z,
    by Wilson and Hilferty's cube-root approximation (relative error below 1e-3 for
    dof > 50 in the upper tail; scipy is not available)."""
    c = 2.0 / (9.0 * dof)
    return dof * (1.0 - c + z * math.sqrt(c)) ** 3


@pytest.fixture(scope="module")
def small_maps():
    radiance = random_radiance(64, 32, seed=11)
    return {
        "plain": envmis.EnvMap(radiance, compensate=False),
        "compensated": envmis.EnvMap(radiance),
        "y-up": envmis.EnvMap(radiance, axes="y-up"),
        "equal-area": envmis.EnvMap(random_radiance(32, 32, seed=12), mapping="equal-area"),
    }


@pytest.mark.parametrize("name", ["plain", "compensated", "y-up", "equal-area"])
def test_the_pdf_of_a_sampled_direction_is_the_pdf_the_sample_reports(small_maps, name):
    env = small_maps[name]
    s = env.sample(envmis.uniform_points(20000, seed=5))
    assert s.direction.shape == (20000, 3) and s.pdf.shape == (20000,)
    assert s.radiance.shape == (20000, 3) and s.uv.shape == (20000, 2)
    assert all(a.dtype == np.float32 for a in s)
    np.testing.assert_allclose(np.linalg.norm(s.direction, axis=1), 1.0, atol=2e-6)
    assert np.all((s.uv >= 0) & (s.uv < 1))
    assert np.all(s.pdf > 0)
    # A direction rounded to float32 can cross into the next texel (or row of sin theta):
    # nearly all agree to float rounding, none is far off.
    relative = np.abs(env.pdf(s.direction) / s.pdf - 1)
    assert np.mean(relative < 1e-4) > 0.995
    radiance_agrees = np.all(env.eval(s.direction) == s.radiance, axis=1)
    assert np.mean(radiance_agrees) > 0.995


def test_the_samples_follow_the_density_by_a_chi_square_test():
    env = envmis.EnvMap(random_radiance(16, 8, seed=3, sun=False), alpha=0.25)
    n = 200_000
    s = env.sample(envmis.uniform_points(n, seed=21))
    texel = np.floor(s.uv * [16, 8]).astype(int)
    counts = np.bincount(texel[:, 1] * 16 + texel[:, 0], minlength=128)
    p = env.density.ravel().astype(np.float64)
    p /= p.sum()
    assert np.all(counts[p == 0] == 0), "a texel the compensation zeroed was sampled"
    live = p > 0
    expected = n * p[live]
    chi2 = np.sum((counts[live] - expected) ** 2 / expected)
    dof = int(live.sum()) - 1
    assert dof > 50
    # The 1 - 1e-4 quantile (z = 3.719): a correct build fails once in 10^4 seeds, and
    # this seed is fixed; sampling by luminance alone (no sin theta) gives chi2 > 10^4.
    assert chi2 < wilson_hilferty(dof, 3.719), (chi2, dof)


@pytest.mark.parametrize("mapping", ["equirect", "equal-area"])
def test_the_pdf_integrates_to_one_over_the_sphere(mapping):
    env = envmis.EnvMap(random_radiance(16, 16, seed=4), alpha=0.5, mapping=mapping)
    # Midpoints of a 1024 x 512 grid in (phi, theta): whole subcells per texel for equirect.
    phi = (np.arange(1024) + 0.5) * (2 * np.pi / 1024)
    theta = (np.arange(512) + 0.5) * (np.pi / 512)
    t, f = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(t) * np.cos(f), np.sin(t) * np.sin(f), np.cos(t)], axis=-1).reshape(-1, 3)
    pdf = env.pdf(d.astype(np.float32)).astype(np.float64)
    integral = np.sum(pdf * np.sin(t).ravel()) * (2 * np.pi / 1024) * (np.pi / 512)
    assert abs(integral - 1) < (2e-3 if mapping == "equirect" else 1e-2)


def test_the_density_is_the_luminance_times_sin_theta_of_the_row():
    radiance = random_radiance(32, 16, seed=6)
    env = envmis.EnvMap(radiance, compensate=False)
    sin_theta = np.sin(np.pi * (np.arange(16) + 0.5) / 16)
    expected = (radiance.astype(np.float64) @ REC709) * sin_theta[:, None]
    np.testing.assert_allclose(env.density, expected, rtol=1e-5)


@needs_cli
def test_sampling_is_bit_identical_to_the_command_for_the_same_seed(tmp_path):
    n, seed = 3000, 7
    result = run_cli("sample", PARK, "-n", n, "--seed", seed, "-o", tmp_path / "samples.csv")
    assert result.returncode == 0, result.stderr
    csv = np.loadtxt(tmp_path / "samples.csv", delimiter=",", skiprows=1, dtype=np.float64).astype(np.float32)
    s = envmis.load(PARK).sample(envmis.uniform_points(n, seed))
    assert np.array_equal(bits(s.uv), bits(csv[:, 0:2]))
    assert np.array_equal(bits(s.direction), bits(csv[:, 2:5]))
    assert np.array_equal(bits(s.pdf), bits(csv[:, 5]))


def test_uniform_points_are_on_the_24_bit_grid_and_repeat_for_a_seed():
    u = envmis.uniform_points(1000, seed=3)
    assert u.shape == (1000, 2) and u.dtype == np.float32
    assert np.all((u >= 0) & (u < 1)) and np.all(u * 2**24 == np.floor(u * 2**24))
    assert np.array_equal(u, envmis.uniform_points(1000, seed=3))
    assert not np.array_equal(u, envmis.uniform_points(1000, seed=4))


@pytest.mark.parametrize("mapped", [True, False])
def test_a_saved_table_loads_as_the_same_map_bit_for_bit(tmp_path, mapped):
    env = envmis.EnvMap(random_radiance(64, 32, seed=8), alpha=1.5)
    env.save(tmp_path / "map.envmis")
    table = envmis.load_table(tmp_path / "map.envmis", mapped=mapped)
    assert isinstance(table, envmis.EnvMap) and table.mapped == mapped
    assert table.source == env.source and table.source["name"] == "array"
    assert table.options == env.options and table.stats == env.stats
    u = envmis.uniform_points(5000, seed=9)
    for a, b in zip(env.sample(u), table.sample(u)):
        assert np.array_equal(bits(a), bits(b))
    assert np.array_equal(bits(table.density), bits(env.density))
    assert np.array_equal(bits(table.radiance), bits(env.radiance))
    # load() recognises a table by its magic.
    assert np.array_equal(envmis.load(tmp_path / "map.envmis").sample(u).pdf, env.sample(u).pdf)


def test_a_saved_binned_map_loads_with_the_same_bins(tmp_path):
    binned = envmis.load(PARK, bins=9)
    binned.save(tmp_path / "binned.envmis", compact=True)
    table = envmis.load_table(tmp_path / "binned.envmis")
    assert isinstance(table, envmis.BinnedEnvMap)
    assert (table.bins, table.classes, table.lobe_exponents) == (9, 3, binned.lobe_exponents)
    # The table records the options with its own encoding, as precompute --compact does.
    assert table.source == {**binned.source, "build_options": binned.source["build_options"].replace(
        "compact=0", "compact=1")} and table.source["name"] == PARK.name
    normals = np.tile(np.array([[0, 0, 1]], np.float32), (1000, 1))
    u = envmis.uniform_points(1000, seed=2)
    choices = envmis.uniform_points(500, seed=3).reshape(-1)
    # Compact: the RGBE-rounded map, which a .hdr source already is.
    assert np.array_equal(bits(table.sample(u, normals, choices, 1).pdf),
                          bits(binned.sample(u, normals, choices, 1).pdf))


@needs_cli
@pytest.mark.parametrize("keywords, compact, flags", [
    ({}, False, []),
    ({"alpha": 2.0, "bins": 9, "axes": "y-up"}, True, ["--alpha", "2", "--bins", "9", "--axes", "y-up", "--compact"]),
])
def test_a_table_saved_from_python_is_up_to_date_for_precompute_with_the_same_options(tmp_path, keywords, compact,
                                                                                       flags):
    table, summary = tmp_path / "park.envmis", tmp_path / "summary.json"
    envmis.load(PARK, **keywords).save(table, compact=compact)
    statuses = []
    uncompensated = list(flags)  # --alpha refused with --no-compensate
    if "--alpha" in uncompensated:
        del uncompensated[uncompensated.index("--alpha"):uncompensated.index("--alpha") + 2]
    for more in (flags, uncompensated + ["--no-compensate"]):
        result = run_cli("precompute", PARK, "-o", table, "--summary", summary, *more)
        assert result.returncode == 0, result.stderr
        statuses += [entry["status"] for entry in json.loads(summary.read_text())["results"]]
    # Other options rebuild it.
    assert statuses == ["up-to-date", "written"]


def mapping_of(address):
    """The file (or "" for anonymous memory) of this process's mapping holding address."""
    with open("/proc/self/maps") as maps:
        for line in maps:
            fields = line.split(maxsplit=5)
            low, high = (int(a, 16) for a in fields[0].split("-"))
            if low <= address < high:
                return fields[5].strip() if len(fields) == 6 else ""
    return None


def test_the_views_copy_nothing_and_cannot_be_written(tmp_path):
    radiance = random_radiance(32, 16, seed=1)
    env = envmis.EnvMap(radiance)
    for name in ("radiance", "density"):
        first, second = getattr(env, name), getattr(env, name)
        assert np.shares_memory(first, second), name
        assert not first.flags.writeable and first.base is not None, name
        with pytest.raises(ValueError):
            first[0, 0] = 1
    assert env.radiance.shape == (16, 32, 3) and env.density.shape == (16, 32)
    assert not np.shares_memory(env.radiance, radiance), "the map holds a copy of the array"
    env.save(tmp_path / "map.envmis")
    table = envmis.load_table(tmp_path / "map.envmis")
    assert table.mapped and np.shares_memory(table.radiance, table.radiance)


@pytest.mark.skipif(not os.path.exists("/proc/self/maps"), reason="needs Linux's /proc/self/maps")
def test_a_mapped_tables_radiance_view_is_the_file_mapping_itself(tmp_path):
    path = tmp_path / "map.envmis"
    envmis.EnvMap(random_radiance(64, 32, seed=3)).save(path)
    mapped, copied = envmis.load_table(path), envmis.load_table(path, mapped=False)
    assert mapped.mapped and not copied.mapped
    first, last = mapped.radiance.__array_interface__["data"][0], mapped.radiance[-1, -1, 2:].ctypes.data
    assert mapping_of(first) == mapping_of(last) == str(path)
    assert mapping_of(copied.radiance.ctypes.data) != str(path)
    assert np.array_equal(mapped.radiance, copied.radiance)


def test_a_view_keeps_its_map_alive_and_only_while_it_exists():
    radiance = random_radiance(32, 16, seed=2, sun=False)
    env = envmis.EnvMap(radiance)
    alive = weakref.ref(env)
    view = env.radiance
    del env
    gc.collect()
    assert alive() is not None, "the map went while a view of its pixels exists"
    assert np.array_equal(view, radiance)
    del view
    gc.collect()
    assert alive() is None, "the map outlives its last view"


def test_nan_infinite_and_negative_pixels_are_replaced_and_counted():
    radiance = random_radiance(16, 8, seed=1)
    radiance[0, 0] = [np.nan, np.nan, 1]
    radiance[1, 1, 2] = np.inf
    radiance[2, 2, 0] = -1
    env = envmis.EnvMap(radiance)
    assert env.stats["bad_pixels"] == {"nan": 2, "infinite": 1, "negative": 1}
    assert env.radiance[0, 0, 0] == 0 and env.radiance[1, 1, 2] == 0 and env.radiance[2, 2, 0] == 0


@pytest.mark.parametrize(
    "u, given",
    [
        (np.zeros((10, 3), np.float32), "a float32 array of shape (10, 3)"),
        (np.zeros(10, np.float32), "a float32 array of shape (10,)"),
        (np.zeros((10, 2), complex), "a complex128 array of shape (10, 2)"),
        (np.zeros((10, 2), bool), "a bool array of shape (10, 2)"),
        ([[0.5, 0.5, 0.5]], "a float64 array of shape (1, 3)"),
        ("points", "a <class 'str'>"),
        (None, "a <class 'NoneType'>"),
    ],
)
def test_points_of_another_shape_or_of_non_real_values_are_rejected_with_a_clear_message(small_maps, u, given):
    with pytest.raises(ValueError) as error:
        small_maps["plain"].sample(u)
    assert str(error.value) == f"envmis.EnvMap.sample: u must be an array of real numbers of shape (N, 2); got {given}"


def test_directions_and_radiance_of_another_shape_are_rejected(small_maps):
    with pytest.raises(ValueError, match=r"envmis.EnvMap.pdf: directions must be an array of real numbers of shape \(N, 3\)"):
        small_maps["plain"].pdf(np.zeros((4, 2), np.float32))
    with pytest.raises(ValueError, match=r"envmis.EnvMap.eval: directions .* got a complex128"):
        small_maps["plain"].eval(np.zeros((4, 3), complex))
    with pytest.raises(ValueError, match=r"envmis.EnvMap: radiance must be an array of real numbers of shape \(H, W, 3\); got a float32 array of shape \(8, 16, 4\)"):
        envmis.EnvMap(np.zeros((8, 16, 4), np.float32))


def test_float64_lists_strided_views_and_single_vectors_give_the_results_of_float32_arrays(small_maps):
    # Values that float32 holds exactly, so that the conversion changes nothing.
    u = envmis.uniform_points(64, seed=2)
    env = small_maps["compensated"]
    expected = env.sample(u)
    wide = np.zeros((64, 4), np.float32)
    wide[:, ::2] = u
    for given in (u.astype(np.float64), u.tolist(), wide[:, ::2], np.asfortranarray(u)):
        got = env.sample(given)
        for a, b in zip(got, expected):
            assert np.array_equal(a, b)
    d = expected.direction
    assert np.array_equal(env.pdf(d.astype(np.float64)), env.pdf(d))
    assert np.array_equal(env.eval(d[::-1][::-1].tolist()), env.eval(d))
    assert np.array_equal(env.pdf(d[5]), env.pdf(d[5:6]))  # a single (3,) direction is one row
    assert env.pdf(tuple(float(x) for x in d[5])).shape == (1,)
    radiance = np.random.default_rng(1).random((8, 16, 3)).astype(np.float32)
    built32, built64 = envmis.EnvMap(radiance), envmis.EnvMap(radiance.astype(np.float64))
    assert np.array_equal(built32.density, built64.density)
    assert np.array_equal(envmis.EnvMap(radiance[::-1][::-1]).density, built32.density)
    # out= is never converted: results must land in the caller's float32 arrays.
    out = env.sample(u)
    with pytest.raises(ValueError, match=r"out.pdf must be a float32 array of shape \(64,\); got a float64"):
        env.sample(u, out=out._replace(pdf=np.zeros(64)))


@needs_cli
def test_the_version_is_the_projects():
    assert envmis.__version__ == subprocess.run([CLI, "--version"], capture_output=True, text=True,
                                               check=True).stdout.split()[-1]


def test_directions_and_normals_that_are_not_finite_or_zero_give_nan_and_the_others_do_not():
    binned = envmis.load(PARK, bins=9)
    plain = binned.plain
    bad = np.array([[np.nan, 0, 1], [np.inf, 0, 0], [0, 0, 0], [0, 0, 1]], np.float32)
    for pdf in (plain.pdf(bad), binned.pdf(bad, np.tile([0, 0, 1], (4, 1)).astype(np.float32),
                                           np.full(4, 0.5, np.float32))):
        assert np.isnan(pdf[:3]).all() and np.isfinite(pdf[3]), pdf
    radiance = plain.eval(bad)
    assert np.isnan(radiance[:3]).all() and np.isfinite(radiance[3]).all()
    samples = binned.sample(np.full((4, 2), 0.5, np.float32), bad, np.full(4, 0.5, np.float32))
    assert np.isnan(samples.pdf[:3]).all() and np.isnan(samples.direction[:3]).all()
    assert samples.pdf[3] > 0 and np.isfinite(samples.direction[3]).all()
    pdf = binned.pdf(np.tile([0, 0, 1], (4, 1)).astype(np.float32), bad, np.full(4, 0.5, np.float32))
    assert np.isnan(pdf[:3]).all() and np.isfinite(pdf[3])


def test_a_binned_map_samples_with_the_pdf_it_reports_and_checks_its_normals():
    binned = envmis.load(PARK, bins=9)
    assert binned.lobe_class(0) == 0 and binned.lobe_class(200) == 2
    for exponent in (float("nan"), -1.0, float("inf")):
        with pytest.raises(ValueError, match="phong_exponent"):
            binned.lobe_class(exponent)
    assert binned.complete(binned.classes - 1) in (True, False)
    with pytest.raises(ValueError, match="lobe: 99 is not a class"):
        binned.complete(99)
    rng = np.random.default_rng(3)
    normals = rng.normal(size=(5000, 3)).astype(np.float32)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    choices = envmis.uniform_points(2500, seed=9).reshape(-1)
    for lobe in range(binned.classes):
        s = binned.sample(envmis.uniform_points(5000, seed=lobe), normals, choices, lobe)
        assert np.mean(np.abs(binned.pdf(s.direction, normals, choices, lobe) / s.pdf - 1) < 1e-4) > 0.995
    plain = binned.plain
    assert isinstance(plain, envmis.EnvMap) and not plain.compensated and plain.width == binned.width
    u = envmis.uniform_points(4, seed=1)
    with pytest.raises(ValueError, match=r"normals must be an array of shape \(N, 3\) with N = 4"):
        binned.sample(u, normals[:3], choices[:4])
    with pytest.raises(ValueError, match=r"normals must be an array of real numbers of shape \(N, 3\); got a float32 array of shape \(4, 2\)"):
        binned.pdf(np.zeros((4, 3), np.float32), np.zeros((4, 2), np.float32), choices[:4])
    assert np.array_equal(binned.pdf(s.direction[:4], normals[:4].astype(np.float64), choices[:4].tolist(), lobe),
                          binned.pdf(s.direction[:4], normals[:4], choices[:4], lobe))
    with pytest.raises(ValueError, match=r"choices must be an array of shape \(N,\) with N = 4"):
        binned.sample(u, normals[:4], choices[:3])
    with pytest.raises(ValueError, match=r"choices"):
        binned.sample(u, normals[:4], np.full(4, 1.0, np.float32))
    with pytest.raises(ValueError, match=r"lobe 3 is not a lobe class of this map \(0 to 2\)"):
        binned.sample(u, normals[:4], choices[:4], lobe=3)


def test_glossy_bins_seen_obliquely_sample_and_weigh_by_their_view_cosines():
    binned = envmis.load(PARK, bins=9)
    rng = np.random.default_rng(4)
    normals = rng.normal(size=(2000, 3)).astype(np.float32)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    choices = envmis.uniform_points(1000, seed=5).reshape(-1)
    u = envmis.uniform_points(2000, seed=6)
    head_on = binned.sample(u, normals, choices, 1)
    assert np.array_equal(head_on.pdf, binned.sample(u, normals, choices, 1, view_cos=np.ones(2000, np.float32)).pdf)
    # Seen edge-on every glossy bin with a view limit samples the plain density (through
    # the cells: equal to the plain map's up to fixed-point rounding).
    edge_on = binned.sample(u, normals, choices, 1, view_cos=np.zeros(2000, np.float32))
    plain = binned.plain

    def plain_share(s):
        return np.mean(np.isclose(s.pdf, plain.pdf(s.direction), rtol=1e-3))

    assert plain_share(edge_on) > plain_share(head_on)
    view_cos = rng.uniform(size=2000).astype(np.float32)
    s = binned.sample(u, normals, choices, 1, view_cos=view_cos)
    agree = np.abs(binned.pdf(s.direction, normals, choices, 1, view_cos=view_cos) / s.pdf - 1) < 1e-4
    assert np.mean(agree) > 0.995
    with pytest.raises(ValueError, match=r"view_cos must be an array of shape \(N,\) with N = 2000"):
        binned.sample(u, normals, choices, 1, view_cos=view_cos[:3])
    with pytest.raises(ValueError, match=r"view_cos\[0\] = 1.5.* is outside \[0, 1\]"):
        binned.pdf(s.direction, normals, choices, 1, view_cos=np.full(2000, 1.5, np.float32))


@needs_cli
@pytest.mark.parametrize("case", ["missing", "not an image", "corrupt table", "fifo"])
def test_a_bad_file_raises_the_message_the_command_prints(tmp_path, case):
    path = tmp_path / "input.hdr"
    if case == "not an image":
        path.write_text("this is not an image\n")
    elif case == "fifo":  # a read would wait for a writer for ever
        os.mkfifo(path)
    elif case == "corrupt table":
        path = tmp_path / "map.envmis"
        envmis.EnvMap(random_radiance(16, 8, seed=1)).save(path)
        data = bytearray(path.read_bytes())
        data[-40] ^= 0xFF
        path.write_bytes(bytes(data))
    expected = envmis.TableError if case == "corrupt table" else envmis.ImageError
    with pytest.raises(expected) as error:
        envmis.load(path)
    assert isinstance(error.value, OSError)
    result = run_cli("info", path)
    assert result.returncode != 0
    assert result.stderr.strip() == f"envmis: {error.value}"


@pytest.mark.parametrize(
    "options, message",
    [
        ({"bins": 5}, "bins: 5: expected a square number of bins (g x g octahedral grid) from 1 to 4096"),
        ({"alpha": "fast"}, "alpha: 'fast': expected a number >= 0 or auto"),
        ({"alpha": -1.5}, "alpha: '-1.5': expected a number >= 0 or auto"),
        ({"alpha": "0.5"}, "alpha: '0.5': expected a number >= 0 or auto (a number, not a str)"),
        ({"alpha": "Auto"}, "alpha: 'Auto': expected a number >= 0 or auto"),
        ({"mapping": "equal-area"}, "an equal-area map must be square, this one is 1024x512"),
        ({"axes": "up"}, "up"),
    ],
)
def test_invalid_options_raise_value_errors_that_name_them(options, message):
    with pytest.raises(ValueError) as error:
        envmis.load(PARK, **options)
    assert message in str(error.value)


def test_an_array_map_refuses_alpha_as_a_str_other_than_auto():
    with pytest.raises(ValueError, match=r"^alpha: '0.5': expected a number >= 0 or auto"):
        envmis.EnvMap(random_radiance(16, 8, seed=1), alpha="0.5")


def test_alpha_auto_chooses_a_strength_and_is_recorded_in_the_options():
    env = envmis.EnvMap(random_radiance(64, 32, seed=5), alpha="auto")
    assert env.options["alpha"] in (0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 2, 3)


def test_every_public_name_of_the_module_has_a_stub_and_a_docstring():
    stub = ast.parse((pathlib.Path(envmis.__file__).parent / "_maps.pyi").read_text())
    stubbed = {node.name for node in stub.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))}
    public = {name for name in dir(envmis._maps) if not name.startswith("__")}
    assert public <= stubbed, public - stubbed
    for name in public:
        assert getattr(envmis._maps, name).__doc__, name
    assert "per steradian" in envmis.EnvMap.pdf.__doc__


def test_sample_writes_into_the_arrays_of_out_and_checks_their_shapes(small_maps):
    env = small_maps["compensated"]
    u = envmis.uniform_points(100, seed=4)
    out = env.sample(envmis.uniform_points(100, seed=5))
    again = env.sample(u, out=out)
    assert all(a is b for a, b in zip(again, out))
    for a, b in zip(out, env.sample(u)):
        assert np.array_equal(bits(a), bits(b))
    short = out._replace(uv=np.zeros((99, 2), np.float32))
    with pytest.raises(ValueError, match=r"out.uv must be a float32 array of shape \(100, 2\); got .* \(99, 2\)"):
        env.sample(u, out=short)


def test_a_read_only_out_array_is_refused_naming_it(small_maps):
    env = small_maps["plain"]
    u = envmis.uniform_points(10, seed=1)
    out = env.sample(u)
    out.pdf.flags.writeable = False
    with pytest.raises(ValueError, match=r"^envmis.EnvMap.sample: out.pdf is not writeable$"):
        env.sample(u, out=out)


@pytest.fixture(scope="module")
def park_binned():
    return envmis.load(PARK, bins=9)


def sample_call(kind, small_maps, park_binned):
    """The three samplers taking points u (N, 2), each as f(u, out=None)."""
    if kind == "EnvMap":
        return lambda u, out=None: small_maps["plain"].sample(u, out=out)
    if kind == "BinnedEnvMap":
        normals = np.tile(np.array([[0, 0, 1]], np.float32), (16, 1))
        choices = np.linspace(0, 0.99, 16, dtype=np.float32)
        return lambda u, out=None: park_binned.sample(u, normals, choices, 1, out=out)
    wo = np.tile(np.array([[0.6, 0.0, 0.8]], np.float32), (16, 1))
    return lambda u, out=None: envmis.Bsdf.ggx(0.2).sample(wo, u)


@pytest.mark.parametrize("kind", ["EnvMap", "BinnedEnvMap", "Bsdf"])
@pytest.mark.parametrize("value, shown", [(1.0, "1"), (-0.1, "-0.1"), (np.nan, "nan"), (2.5, "2.5"), (np.inf, "inf")])
def test_points_outside_the_unit_square_are_refused_naming_the_first(small_maps, park_binned, kind, value, shown):
    sample = sample_call(kind, small_maps, park_binned)
    u = envmis.uniform_points(16, seed=3)
    u[12, 1] = value
    u[14, 0] = value
    with pytest.raises(ValueError) as error:
        sample(u)
    assert str(error.value) == f"envmis.{kind}.sample: u[12, 1] = {shown} is outside [0, 1)"


@pytest.mark.parametrize("kind", ["EnvMap", "BinnedEnvMap", "Bsdf"])
def test_the_ends_of_the_unit_square_are_accepted(small_maps, park_binned, kind):
    u = envmis.uniform_points(16, seed=3)
    u[0] = 0.0
    u[1] = np.nextafter(np.float32(1), np.float32(0))
    assert np.all(np.isfinite(sample_call(kind, small_maps, park_binned)(u)[1]))


def test_a_refused_u_leaves_the_out_arrays_untouched(small_maps):
    env = small_maps["compensated"]
    u = envmis.uniform_points(5000, seed=6)
    out = env.sample(u)
    before = [a.copy() for a in out]
    bad = envmis.uniform_points(5000, seed=7)
    bad[4999, 0] = 1.0
    with pytest.raises(ValueError, match=r"u\[4999, 0\] = 1 is outside"):
        env.sample(bad, out=out)
    assert all(np.array_equal(bits(a), bits(b)) for a, b in zip(out, before))


def test_a_plain_map_of_a_binned_one_records_its_own_build_options(park_binned, tmp_path):
    plain = park_binned.plain
    options = plain.source["build_options"]
    assert "compensate=0 alpha=-" in options and options.endswith("bins=0 cell-columns=0"), options
    assert park_binned.source["build_options"].endswith("bins=9 cell-columns=0 bin-cost=1.20000005")
    park_binned.save(tmp_path / "binned.envmis")
    # A table's request is not known beyond its options: its plain map records none.
    assert envmis.load_table(tmp_path / "binned.envmis").plain.source["build_options"] == ""


@needs_cli
def test_a_saved_plain_map_of_a_binned_one_is_up_to_date_only_for_an_uncompensated_precompute(park_binned, tmp_path):
    statuses = []
    for flags in (["--bins", "9"], ["--no-compensate"]):
        table, summary = tmp_path / f"park{len(statuses)}.envmis", tmp_path / "summary.json"
        park_binned.plain.save(table)
        result = run_cli("precompute", PARK, "-o", table, "--summary", summary, *flags)
        assert result.returncode == 0, result.stderr
        statuses += [entry["status"] for entry in json.loads(summary.read_text())["results"]]
    assert statuses == ["written", "up-to-date"]


@pytest.mark.parametrize("first, then, options", [
    (False, True, "compact=1"),   # a full table's map, rounded as precompute --compact rounds it
    (True, True, "compact=1"),
    (False, False, "compact=0"),
    (True, False, ""),            # the rounded map stored full: no build of the source makes it
])
def test_a_table_saved_again_records_the_encoding_it_is_saved_in(tmp_path, first, then, options):
    built = envmis.load(PARK)
    built.save(tmp_path / "first.envmis", compact=first)
    envmis.load_table(tmp_path / "first.envmis").save(tmp_path / "again.envmis", compact=then)
    again = envmis.load_table(tmp_path / "again.envmis").source["build_options"]
    if options:
        assert again == built.source["build_options"].replace("compact=0", options)
    else:
        assert again == ""
