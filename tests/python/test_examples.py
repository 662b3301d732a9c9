"""The examples in examples/python run on the bundled maps and write their PNGs."""

import os
import re
import struct
import subprocess
import sys

import pytest

SOURCE = os.environ.get("ENVMIS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXAMPLES = os.path.join(SOURCE, "examples", "python")
MAPS = os.path.join(SOURCE, "data", "envmaps")


def run_example(script, *arguments):
    env = dict(os.environ, MPLBACKEND="Agg", OCIO=os.path.join(SOURCE, "data", "ocio", "config.ocio"))
    return subprocess.run([sys.executable, os.path.join(EXAMPLES, script), *map(str, arguments)],
                          capture_output=True, text=True, env=env, timeout=120)


def png_size(path):
    """(width, height) from a PNG's IHDR, after checking its signature."""
    with open(path, "rb") as f:
        header = f.read(24)
    assert header[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert header[12:16] == b"IHDR"
    return struct.unpack(">II", header[16:24])


def test_the_histogram_example_writes_a_png_and_its_samples_fit_the_pdf(tmp_path):
    output = tmp_path / "histogram.png"
    result = run_example("sample_histogram.py", os.path.join(MAPS, "rooitou_park_1k.hdr"), "-o", output,
                         "--samples", 200_000, "--bins", "32x16", "--alpha", "none")
    assert result.returncode == 0, result.stderr
    width, height = png_size(output)
    assert width >= 600 and height >= 200 and output.stat().st_size > 20_000
    per_degree = float(re.search(r"([0-9.]+) per degree", result.stdout).group(1))
    # The plain density spreads the samples over about 490 bins expecting >= 5: a correct
    # sampler gives 1 +- 0.064 (sqrt(2 / dof)); samples put in the wrong rows give ~10^5.
    assert 0.75 <= per_degree <= 1.25, result.stdout


def test_the_alpha_study_example_plots_a_panel_per_map(tmp_path):
    output = tmp_path / "alpha.png"
    result = run_example("alpha_study.py", os.path.join(MAPS, "rooitou_park_1k.hdr"), os.path.join(MAPS, "studio.exr"),
                         "-o", output, "--points", 8)
    assert result.returncode == 0, result.stderr
    width, height = png_size(output)
    assert width >= 600 and height >= 250 and output.stat().st_size > 20_000
    assert re.search(r"rooitou_park_1k.hdr: lambert best alpha [0-9.]+ \(", result.stdout), result.stdout
    assert "studio.exr:" in result.stdout


@pytest.mark.parametrize("script", ["sample_histogram.py", "alpha_study.py"])
def test_an_example_given_a_missing_map_fails_with_one_clear_line(tmp_path, script):
    result = run_example(script, tmp_path / "missing.hdr", "-o", tmp_path / "out.png")
    assert result.returncode != 0
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(script + ": ") and "missing.hdr" in lines[0], result.stderr
    assert not (tmp_path / "out.png").exists()


def test_the_readmes_python_snippet_run_as_written_saves_a_picture_of_the_sun_and_the_sky(tmp_path):
    with open(os.path.join(SOURCE, "README.md"), encoding="utf-8") as f:
        readme = f.read()
    snippet = re.search(r"## Python\n.*?```python\n(.*?)```", readme, re.S).group(1)
    os.symlink(os.path.join(SOURCE, "data"), tmp_path / "data")  # its paths are relative to the checkout
    env = dict(os.environ, MPLBACKEND="Agg", OCIO=os.path.join(SOURCE, "data", "ocio", "config.ocio"))
    result = subprocess.run([sys.executable, "-c", snippet], cwd=tmp_path, capture_output=True, text=True, env=env,
                            timeout=120)
    assert result.returncode == 0, result.stderr
    import matplotlib.image
    import numpy as np
    picture = (matplotlib.image.imread(tmp_path / "samples.png")[..., :3] * 255).astype(int)
    # The histogram's own colours, left of where a colour bar would be: a linear scale on a
    # sunny map draws nearly every bin in the darkest colour (3 distinct colours, measured),
    # a log scale the sky's gradations and the horizon too (45).
    axes = picture[:, : int(0.7 * picture.shape[1])].reshape(-1, 3)
    coloured = axes[axes.max(axis=1) - axes.min(axis=1) > 40]
    assert len(np.unique(coloured // 8, axis=0)) >= 20
