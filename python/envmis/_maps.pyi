"""envmis maps, tables and sampling (type stubs; the docstrings are in the module).

Directions: float32 unit vectors in the map's world frame. pdf: per steradian.
Radiance: linear RGB in the map's working colour space. uv: image points in [0, 1)^2.
Array arguments take any array-like of real numbers of their shape (float64, lists,
strided views: converted to a float32 copy; a single vector where (N, k) is expected is
one row); an `out` array must be float32, C-contiguous and writeable.
Points u must satisfy 0 <= u < 1 in every coordinate (NaN fails), else ValueError naming
the first: note that rng.random(...).astype(np.float32) can round up to 1.0 (use
envmis.uniform_points or rng.random(..., dtype=np.float32)).
An `out` array must be writeable. alpha is a number >= 0 or the str "auto", no other str.
"""

import os
from typing import Literal, NamedTuple, TypedDict

import numpy as np
import numpy.typing as npt

_F32 = npt.NDArray[np.float32]
_In = npt.ArrayLike  # real numbers of the documented shape; converted to float32 (a copy) unless it is C-contiguous float32
_Path = str | os.PathLike[str]

__version__: str

class ImageError(OSError): ...
class TableError(OSError): ...

class Samples(NamedTuple):
    direction: _F32  # (N, 3) unit vectors, world frame
    pdf: _F32  # (N,) per steradian
    radiance: _F32  # (N, 3) linear RGB, working space
    uv: _F32  # (N, 2) image points in [0, 1)^2

class BadPixels(TypedDict):
    nan: int
    infinite: int
    negative: int

class MapStats(TypedDict):
    bad_pixels: BadPixels
    mean_luminance: float
    threshold: float
    max_luminance: float
    min_positive_luminance: float
    zeroed_texels: int
    fallback: Literal["none", "uncompensated", "uniform"]

class MapOptions(TypedDict):
    compensate: bool
    alpha: float
    axes: str
    mapping: Literal["equirect", "equal-area"]
    luma: tuple[float, float, float]

class MapSource(TypedDict):
    name: str
    content_hash: int
    input_colorspace: str
    working_colorspace: str
    build_options: str

class EnvMap:
    def __init__(
        self,
        radiance: _In,
        *,
        compensate: bool = True,
        alpha: float | Literal["auto"] = 1.0,
        axes: str = "z-up",
        mapping: Literal["equirect", "equal-area"] = "equirect",
        colorspace: str | None = None,
        working_space: str = "lin_rec709",
    ) -> None: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def compensated(self) -> bool: ...
    @property
    def complete(self) -> bool: ...
    @property
    def options(self) -> MapOptions: ...
    @property
    def stats(self) -> MapStats: ...
    @property
    def source(self) -> MapSource: ...
    @property
    def mapped(self) -> bool: ...
    @property
    def from_table(self) -> bool: ...  # read from a table file (compare's default alpha is then 0 uncompensated)
    @property
    def radiance(self) -> _F32: ...  # (H, W, 3), read-only view
    @property
    def density(self) -> _F32: ...  # (H, W), read-only, computed on first access
    def sample(self, u: _In, *, out: Samples | None = None) -> Samples: ...
    def pdf(self, directions: _In) -> _F32: ...
    def eval(self, directions: _In) -> _F32: ...
    def save(self, path: _Path, *, compact: bool = False) -> None: ...

class BinnedEnvMap:
    @property
    def plain(self) -> EnvMap: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def bins(self) -> int: ...
    @property
    def diffuse_bins(self) -> int: ...
    @property
    def classes(self) -> int: ...
    @property
    def lobe_exponents(self) -> list[float]: ...
    @property
    def source(self) -> MapSource: ...
    @property
    def mapped(self) -> bool: ...
    @property
    def from_table(self) -> bool: ...  # read from a table file (compare's default alpha is then 0 uncompensated)
    def lobe_class(self, phong_exponent: float) -> int: ...
    def complete(self, lobe: int) -> bool: ...
    def sample(
        self, u: _In, normals: _In, choices: _In, lobe: int = 0, *, view_cos: _In | None = None, out: Samples | None = None
    ) -> Samples: ...
    def pdf(self, directions: _In, normals: _In, choices: _In, lobe: int = 0, *, view_cos: _In | None = None) -> _F32: ...
    def eval(self, directions: _In) -> _F32: ...
    def save(self, path: _Path, *, compact: bool = False) -> None: ...

def load(
    path: _Path,
    *,
    compensate: bool = True,
    alpha: float | Literal["auto"] | None = None,
    axes: str = "z-up",
    mapping: Literal["equirect", "equal-area"] = "equirect",
    colorspace: str | None = None,
    working_space: str = "lin_rec709",
    bins: int = 0,
    cell_columns: int = 0,
    bin_cost: float = 1.2,
) -> EnvMap | BinnedEnvMap: ...
def load_table(path: _Path, *, mapped: bool = True) -> EnvMap | BinnedEnvMap: ...
def uniform_points(n: int, seed: int) -> _F32: ...
def _time_sample_many(map: EnvMap, u: _In, repeats: int, *, fresh_outputs: bool = False) -> float: ...
