"""envmis._study: the variance study from Python gives what `envmis compare` gives.

A small synthetic map (64 x 32: a sky gradient and a small sun) keeps every study
fast; it reaches the command as a table file saved from Python, so both sides study the
same texels. Seeds are fixed: every check is deterministic.
"""

import json
import os
import subprocess
import threading
import time
import _thread

import numpy as np
import pytest

import envmis

CLI = os.environ.get("ENVMIS_CLI", "")
TIMING_KEYS = {"ns_per_estimate", "efficiency", "efficiency_ratio_vs_mis"}
STUDY_BSDFS = "lambert,phong:20,ggx:0.2"
STUDY_TECHNIQUES = "env,bsdf,mis-balance,mis-power,mis-balance-comp,mis-optimal-comp,one-sample,mis-balance-bins"


def synthetic_radiance(width=64, height=32):
    """A sky brightening towards the zenith (row 0) with a small, bright sun."""
    rows = np.linspace(1.0, 0.2, height, dtype=np.float32)[:, None]
    sky = np.repeat(rows, width, axis=1)
    radiance = np.stack([0.6 * sky, 0.8 * sky, 1.0 * sky], axis=-1).astype(np.float32)
    radiance[8:10, 40:42] = (400.0, 380.0, 300.0)
    return np.ascontiguousarray(radiance)


@pytest.fixture(scope="module")
def env():
    return envmis.EnvMap(synthetic_radiance())


@pytest.fixture(scope="module")
def table(env, tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "synthetic.envmis"
    env.save(str(path))
    return path


def run_cli(*arguments):
    if not CLI:
        pytest.skip("ENVMIS_CLI is not set (ctest sets it)")
    env = dict(os.environ, OCIO=os.path.join(os.environ["ENVMIS_SOURCE_DIR"], "data", "ocio", "config.ocio"))
    return subprocess.run([CLI, *map(str, arguments)], capture_output=True, text=True, env=env, timeout=120)


def cli_json(table, tmp_path, *arguments):
    output = tmp_path / "compare.json"
    result = run_cli("compare", table, "--json", output, *arguments)
    assert result.returncode == 0, result.stderr
    return json.loads(output.read_text())


def cli_error(*arguments):
    result = run_cli(*arguments)
    assert result.returncode != 0
    line = result.stderr.strip()
    assert line.startswith("envmis: "), line
    return line[len("envmis: "):]


def without_timings(record):
    return {key: value for key, value in record.items() if key not in TIMING_KEYS}


# --- compare equals the command -------------------------------------------------------


def test_compare_records_equal_the_commands_json_for_the_same_arguments_and_seed(env, table, tmp_path):
    expected = cli_json(table, tmp_path, "--seed", 7, "--spp", 96, "--points", 5, "--bsdf", STUDY_BSDFS,
                        "--techniques", STUDY_TECHNIQUES, "--bins", 9, "--threads", 2, "--exact")
    got = envmis.compare(env, bsdfs=STUDY_BSDFS, techniques=STUDY_TECHNIQUES.split(","), spp=96, points=5, seed=7,
                         bins=9, threads=1, exact=True)
    assert [without_timings(r) for r in got.records] == [without_timings(r) for r in expected["results"]]
    assert all(set(r) == set(e) for r, e in zip(got.records, expected["results"]))
    assert got.exact == expected["exact"]
    for key in ("width", "height", "alpha", "alpha_auto", "spp", "seed", "env_samples", "bsdf_samples",
                "points_done", "albedo", "bsdf_alpha", "bins", "points"):
        assert got.inputs[key] == expected["inputs"][key], key


def test_view_angle_and_bin_cost_give_the_commands_records(env, table, tmp_path):
    expected = cli_json(table, tmp_path, "--seed", 3, "--spp", 32, "--points", 4, "--bsdf", "lambert,phong:50",
                        "--techniques", "mis-balance,mis-balance-bins", "--bins", 9, "--view-angle", 60,
                        "--bin-cost", 2.5)
    got = envmis.compare(env, bsdfs="lambert,phong:50", techniques=["mis-balance", "mis-balance-bins"], spp=32,
                         points=4, seed=3, bins=9, view_angle=60.0, bin_cost=2.5)
    assert [without_timings(r) for r in got.records] == [without_timings(r) for r in expected["results"]]
    assert got.inputs["points"] == expected["inputs"]["points"]
    head_on = envmis.compare(env, bsdfs="lambert,phong:50", techniques=["mis-balance", "mis-balance-bins"], spp=32,
                             points=4, seed=3, bins=9)
    assert head_on.inputs["points"] != got.inputs["points"]


def test_an_uncompensated_table_is_compared_with_the_commands_default_alpha_of_zero(tmp_path):
    path = tmp_path / "plain.envmis"
    envmis.EnvMap(synthetic_radiance(), compensate=False).save(path)
    arguments = dict(bsdfs="lambert,phong:20", techniques=["mis-balance", "mis-balance-comp"], spp=32, points=3, seed=5)
    expected = cli_json(path, tmp_path, "--seed", 5, "--spp", 32, "--points", 3, "--bsdf", arguments["bsdfs"],
                        "--techniques", "mis-balance,mis-balance-comp")
    table = envmis.load_table(path)
    assert table.from_table and not table.compensated
    got = envmis.compare(table, **arguments)
    assert got.inputs["alpha"] == expected["inputs"]["alpha"] == 0
    assert [without_timings(r) for r in got.records] == [without_timings(r) for r in expected["results"]]
    # The same pixels built here, not read from a table: --alpha's default of 1.
    assert envmis.compare(envmis.EnvMap(synthetic_radiance(), compensate=False), **arguments).inputs["alpha"] == 1


def test_the_per_point_arrays_are_the_records_point_variances_in_point_order(env):
    c = envmis.compare(env, bsdfs=["lambert", envmis.Bsdf.phong(20)], techniques=["mis-balance", "bsdf"], spp=64,
                       points=3, seed=3)
    assert c.points_done == c.points_total == 3
    assert c.bsdfs == ["lambert", "phong:20"]
    for record in c.records:
        variances = c.point_variances(record["bsdf"], record["technique"])
        assert variances.dtype == np.float64 and variances.shape == (3,)
        assert variances.tolist() == record["point_variances"]
        assert np.mean(variances) == pytest.approx(record["variance"], rel=1e-12)
    with pytest.raises(KeyError, match="no BSDF ggx:0.1 in this comparison"):
        c.point_variances("ggx:0.1", "bsdf")


def test_alpha_auto_chooses_what_the_command_chooses(env, table, tmp_path):
    expected = cli_json(table, tmp_path, "--alpha", "auto", "--spp", 8, "--points", 4, "--bsdf", STUDY_BSDFS,
                        "--techniques", "mis-balance,mis-balance-comp")["inputs"]
    choice = envmis.choose_alpha(env, bsdfs=STUDY_BSDFS, points=4)
    cli_choice = expected["alpha_choice"]
    assert choice["alpha"] == cli_choice["map_alpha"]
    assert choice["bsdf_alphas"] == cli_choice["bsdf_alpha"]
    assert [c["alpha"] for c in choice["candidates"]] == [c["alpha"] for c in cli_choice["candidates"]]
    assert [c["criterion"] for c in choice["candidates"]] == [c["all"] for c in cli_choice["candidates"]]
    assert [c["per_bsdf"] for c in choice["candidates"]] == [c["per_bsdf"] for c in cli_choice["candidates"]]
    got = envmis.compare(env, bsdfs=STUDY_BSDFS, techniques=["mis-balance", "mis-balance-comp"], spp=8, points=4,
                         alpha="auto")
    assert got.inputs["bsdf_alpha"] == expected["bsdf_alpha"] and got.inputs["alpha_auto"] is True
    # The command's own shape, every figure but the choice's time.
    timeless = [{k: v for k, v in inputs["alpha_choice"].items() if k != "seconds"} for inputs in (got.inputs, expected)]
    assert timeless[0] == timeless[1] and set(got.inputs["alpha_choice"]) == set(expected["alpha_choice"])
    assert got.inputs["albedo"] == expected["albedo"]


def test_choose_alpha_takes_a_radiance_array_as_the_map_it_builds(env):
    from_array = envmis.choose_alpha(synthetic_radiance(), bsdfs="lambert", points=4)
    from_map = envmis.choose_alpha(env, bsdfs="lambert", points=4)
    assert from_array["candidates"] == from_map["candidates"]
    assert from_array["candidates"][0] == {"alpha": 0.0, "criterion": 1.0, "per_bsdf": {"lambert": 1.0}}


# --- statistics -----------------------------------------------------------------------


def test_every_technique_is_unbiased_within_four_standard_errors(env):
    c = envmis.compare(env, bsdfs=STUDY_BSDFS, techniques=STUDY_TECHNIQUES.split(",") + ["mis-var", "mis-optimal-all"],
                       spp=2048, points=4, seed=11, bins=9)
    for r in c.records:
        assert r["std_error"] > 0, r["technique"]
        assert abs(r["mean"] - r["reference"]) <= 4 * r["std_error"], (r["bsdf"], r["technique"])


def test_exact_variances_agree_with_the_measured_variances_at_every_point(env):
    normals = envmis.sphere_points(4)
    compensated = envmis.compensated_map(env, 1.0)
    exact = envmis.exact_variances(compensated, "mis-balance-comp", STUDY_BSDFS, normals=normals, subdivisions=4)
    assert exact.shape == (3, 4) and exact.dtype == np.float64
    c = envmis.compare(env, bsdfs=STUDY_BSDFS, techniques=["mis-balance-comp"], spp=20000, normals=normals, seed=5,
                       alpha=1.0)
    for b, bsdf in enumerate(c.bsdfs):
        measured = c.point_variances(bsdf, "mis-balance-comp")
        rel_se = c.point_variance_rel_se(bsdf, "mis-balance-comp")
        for p in range(4):
            assert abs(measured[p] / exact[b, p] - 1) <= 4 * rel_se[p] + 0.03, (bsdf, p, measured[p], exact[b, p])


def test_a_bsdfs_samples_carry_its_pdf_and_value_and_its_pdf_integrates_to_one():
    rng = np.random.default_rng(2)
    n = 200_000
    wo = np.tile(np.array([[0.6, 0.0, 0.8]], dtype=np.float32), (n, 1))
    for bsdf in (envmis.Bsdf.lambert(), envmis.Bsdf.phong(20), envmis.Bsdf.ggx(0.3)):
        wi, pdf, value = bsdf.sample(wo, rng.random((n, 2), dtype=np.float32))
        drawn = pdf > 0
        assert np.array_equal(pdf[drawn], bsdf.pdf(wo[drawn], wi[drawn]))
        assert np.array_equal(value[drawn], bsdf.eval(wo[drawn], wi[drawn]))
        # Uniform directions over the sphere: E[4 pi pdf] = integral of pdf = 1.
        z = rng.uniform(-1, 1, n)
        phi = rng.uniform(0, 2 * np.pi, n)
        r = np.sqrt(1 - z * z)
        uniform = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1).astype(np.float32)
        integrand = 4 * np.pi * bsdf.pdf(wo, uniform).astype(np.float64)
        assert abs(integrand.mean() - 1) <= 4 * integrand.std() / np.sqrt(n), bsdf.name


# --- names, points, errors ------------------------------------------------------------


def test_every_technique_name_parses_back_to_itself_and_the_defaults_are_among_them():
    names = envmis.techniques()
    assert set(envmis.default_techniques()) <= set(names)
    assert [envmis.Technique.parse(n).name for n in names] == names
    assert envmis.Technique.parse("mis-optimal-comp").adaptive
    assert envmis.Bsdf.parse("phong:50") == envmis.Bsdf.phong(50)
    assert envmis.Bsdf.parse("ggx:0.1").name == "ggx:0.1" and envmis.Bsdf.lambert(0.5).name == "lambert:0.5"


def test_sphere_points_are_unit_normals_of_float32():
    normals = envmis.sphere_points(16)
    assert normals.shape == (16, 3) and normals.dtype == np.float32
    assert np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-6)


def test_an_unknown_bsdf_or_technique_raises_the_commands_message(env, table):
    message = cli_error("compare", table, "--bsdf", "velvet", "--spp", 1)
    with pytest.raises(ValueError) as error:
        envmis.compare(env, bsdfs=["velvet"], spp=1)
    assert str(error.value) == message
    message = cli_error("compare", table, "--techniques", "mis-magic", "--spp", 1)
    with pytest.raises(ValueError) as error:
        envmis.compare(env, techniques=["mis-magic"], spp=1)
    assert str(error.value) == message
    with pytest.raises(ValueError) as error:
        envmis.Technique.parse("mis-magic")
    assert str(error.value) == message


@pytest.mark.parametrize("arguments, message", [
    ({"spp": 0}, "envmis.compare: spp must be 1 to 4294967295; got 0"),
    ({"points": 0}, "envmis.compare: points must be 1 to 1000000; got 0"),
    ({"env_samples": -1}, "envmis.compare: env_samples must be 0 to 65536; got -1"),
    ({"alpha": -1.0}, "envmis.compare: alpha must be a finite number >= 0 or 'auto'; got -1.0"),
    ({"bins": 10, "techniques": ["mis-balance-bins"]},
     "envmis.compare: bins 10: expected a square number g*g of normal bins, g 1 to 64 (e.g. 64, 100, 144)"),
    ({"env_samples": 0, "bsdf_samples": 0, "techniques": ["mis-balance"]}, "an estimate needs at least one sample"),
    ({"view_angle": 90.0}, "envmis.compare: view_angle: a view angle must be 0 to 89.9 degrees, got 90.000000"),
    ({"view_angle": float("nan")}, "envmis.compare: view_angle: a view angle must be 0 to 89.9 degrees, got nan"),
    ({"view_angle": 10.0, "normals": np.array([[0, 0, 1]], np.float32)},
     "envmis.compare: view_angle needs points, not normals (views give theirs)"),
    ({"bin_cost": 0.5}, "envmis.compare: bin_cost must be 1 to 100; got 0.500000"),
    ({"bin_cost": float("inf")}, "envmis.compare: bin_cost must be 1 to 100; got inf"),
])
def test_a_count_out_of_range_is_refused_with_a_clear_message(env, arguments, message):
    with pytest.raises(ValueError) as error:
        envmis.compare(env, **arguments)
    assert str(error.value) == message


@pytest.mark.parametrize("normals, views, message", [
    (np.zeros((4, 3), complex), None, "normals must be an array of real numbers of shape (N, 3); got a complex128 "
                                      "array of shape (4, 3)"),
    (np.ones((4, 2), np.float32), None, "normals must be an array of real numbers of shape (N, 3); got a float32 "
                                        "array of shape (4, 2)"),
    (np.full((2, 3), 0.5, np.float32), None, "normals[0] must be a unit vector; got length 0.866025"),
    (envmis.sphere_points(4), envmis.sphere_points(3), "views must have as many rows as normals (4); got 3"),
    (None, envmis.sphere_points(4), "views needs normals"),
])
def test_shading_points_of_the_wrong_dtype_shape_or_length_are_refused(env, normals, views, message):
    with pytest.raises(ValueError) as error:
        envmis.compare(env, normals=normals, views=views, spp=1)
    assert str(error.value) == "envmis.compare: " + message


def test_a_bsdf_of_the_wrong_type_is_a_type_error(env):
    with pytest.raises(TypeError, match="a BSDF must be a name such as 'phong:50' or an envmis.Bsdf; got int"):
        envmis.compare(env, bsdfs=[3], spp=1)


# --- long runs ------------------------------------------------------------------------


def test_ctrl_c_stops_a_long_run_and_raises_keyboard_interrupt(env):
    # Run to its end, this study would take tens of seconds (10^9 estimates).
    timer = threading.Timer(0.3, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        envmis.compare(env, bsdfs="lambert", techniques=["bsdf"], spp=10**9, points=1, threads=1)
    timer.join()
    assert time.monotonic() - start < 3


def test_progress_reports_the_end_and_an_exception_from_it_stops_the_run(env):
    seen = []
    envmis.compare(env, bsdfs="lambert", techniques=["bsdf"], spp=16, points=3, progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1] == (3, 3)

    def stop(done, total):
        raise RuntimeError("enough")

    start = time.monotonic()
    with pytest.raises(RuntimeError, match="enough"):
        envmis.compare(env, bsdfs="lambert", techniques=["bsdf"], spp=10**9, points=1, threads=1, progress=stop)
    assert time.monotonic() - start < 3
