"""Type stubs of envmis._study: BSDFs, techniques and the variance study.

Units and measures: directions are unit vectors (world frame for shading points, the
local shading frame, z the normal, for Bsdf methods); pdfs per steradian; radiance
linear RGB in the map's working space; a variance is that of ONE estimate's luminance,
in radiance units squared; per-point arrays are in point order.
"""

from typing import Any, Callable, Iterable, Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._maps import BinnedEnvMap, EnvMap

_F32 = npt.NDArray[np.float32]
_In = npt.ArrayLike  # real numbers of the documented shape; converted to float32 (a copy) unless it is C-contiguous float32
_F64 = npt.NDArray[np.float64]
BsdfLike = Union[str, "Bsdf"]
TechniqueLike = Union[str, "Technique"]
# A comma-separated str of names (as --bsdf), or an iterable of names and objects.
Bsdfs = Union[str, Iterable[BsdfLike]]
Techniques = Union[str, Iterable[TechniqueLike]]

class Bsdf:
    """An analytic reflection BSDF: Lambert, energy-normalised Phong or GGX."""

    @staticmethod
    def parse(text: str) -> Bsdf:
        """'lambert[:ALBEDO]', 'phong:N[:ALBEDO]' (0 <= N <= 1e5), 'ggx:A[:F0]' (0.001 <= A <= 1); ValueError."""
    @staticmethod
    def lambert(albedo: Optional[float] = None) -> Bsdf:
        """Grey albedo in [0, 1], default 0.8."""
    @staticmethod
    def phong(n: float, albedo: Optional[float] = None) -> Bsdf:
        """Exponent n in [0, 1e5], grey specular albedo in [0, 1] (default 0.8)."""
    @staticmethod
    def ggx(alpha: float, f0: Optional[float] = None) -> Bsdf:
        """Roughness alpha in [0.001, 1], grey Schlick F0 in [0, 1] (default 0.95/0.64/0.54)."""
    @property
    def name(self) -> str:
        """The name parse() reads back: 'lambert', 'phong:50', 'ggx:0.1'."""
    @property
    def kind(self) -> Literal["lambert", "phong", "ggx"]: ...
    @property
    def albedo(self) -> tuple[float, float, float]:
        """Reflectance (r, g, b): Lambert's albedo, Phong's specular albedo, GGX's F0."""
    @property
    def exponent(self) -> float:
        """Phong's n (0 for the others)."""
    @property
    def alpha(self) -> float:
        """GGX's roughness (0 for the others)."""
    def eval(self, wo: _In, wi: _In) -> _F32:
        """float32 (N, 3) RGB f(wo, wi) cos(theta_i) for float32 (N, 3) local unit vectors."""
    def pdf(self, wo: _In, wi: _In) -> _F32:
        """float32 (N,): solid-angle density (1/sr) of sample(wo) at wi, over the whole sphere."""
    def sample(self, wo: _In, u: _In) -> tuple[_F32, _F32, _F32]:
        """(wi (N, 3), pdf (N,), value (N, 3) = eval(wo, wi)) for wo (N, 3) and u (N, 2) in [0, 1)^2
        (every value 0 <= u < 1, NaN not: ValueError naming the first that is not)."""
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

class Technique:
    """An estimator of direct lighting, by name (envmis.techniques() lists them)."""

    @staticmethod
    def parse(name: str) -> Technique:
        """ValueError with the command's message for an unknown name."""
    @property
    def name(self) -> str: ...
    @property
    def adaptive(self) -> bool:
        """Learns at each point (mis-optimal, mis-var): it has no exact variance."""
    @property
    def compensated(self) -> bool: ...
    @property
    def mixture(self) -> bool: ...
    @property
    def bins(self) -> bool: ...
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

def techniques() -> list[str]:
    """Every technique's name."""

def default_techniques() -> list[str]:
    """The techniques compare runs when none are named, in its order."""

def sphere_points(k: int) -> _F32:
    """float32 (k, 3): k unit normals spread evenly over the sphere (world frame); 1 <= k <= 10^6."""

class Comparison:
    """The result of compare(): compare --json's records, inputs and exact ratios."""

    records: list[dict[str, Any]]
    """One dict per BSDF and technique, the keys of compare --json's "results"; variance is
    that of ONE estimate (radiance units squared); non-finite values are None."""
    inputs: dict[str, Any]
    """compare --json's "inputs" in the same shape (alpha_choice included), less its source_hash and options."""
    exact: Optional[dict[str, dict[str, dict[str, float]]]]
    """With exact=True, {bsdf: {technique: {"ratio", "worst"}}}: exact variance over mis-balance's."""
    @property
    def points_done(self) -> int: ...
    @property
    def points_total(self) -> int: ...
    @property
    def bsdfs(self) -> list[str]: ...
    def point_variances(self, bsdf: BsdfLike, technique: TechniqueLike) -> _F64:
        """float64 (points_done,): each point's variance of ONE estimate, in point order (a copy)."""
    def point_variance_rel_se(self, bsdf: BsdfLike, technique: TechniqueLike) -> _F64:
        """float64 (points_done,): the relative standard error of each point's variance."""

def compare(
    map: EnvMap,
    *,
    bsdfs: Bsdfs = ("lambert", "phong:50", "ggx:0.1"),
    techniques: Optional[Techniques] = None,
    spp: int = 1024,
    points: int = 16,
    normals: Optional[_In] = None,
    views: Optional[_In] = None,
    seed: int = 1,
    threads: int = 0,
    alpha: Union[None, float, Literal["auto"]] = None,
    env_samples: int = 1,
    bsdf_samples: int = 1,
    bins: int = 0,
    view_angle: float = 0.0,
    bin_cost: float = 1.2,
    exact: bool = False,
    name: Optional[str] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> Comparison:
    """The variance study of `envmis compare` (same records for the same arguments and seed).

    alpha None: the map's own strength if compensated, else 0 for a map read from a table
    (map.from_table) and 1 for one built from an image, as the command's default.

    GIL released; Ctrl-C (or an exception from progress) stops it and is raised."""

def exact_variances(
    map: Union[EnvMap, BinnedEnvMap],
    technique: TechniqueLike,
    bsdfs: Bsdfs = ("lambert", "phong:50", "ggx:0.1"),
    *,
    points: int = 16,
    normals: Optional[_In] = None,
    views: Optional[_In] = None,
    env_samples: int = 1,
    bsdf_samples: int = 1,
    subdivisions: int = 1,
) -> _F64:
    """float64 (len(bsdfs), points): exact variance of ONE estimate's luminance (quadrature) by
    `technique` sampling `map` (a compensated map for -comp, a BinnedEnvMap for -bins)."""

def choose_alpha(
    map: Union[EnvMap, _F32],
    *,
    bsdfs: Bsdfs = ("lambert", "phong:50", "ggx:0.1"),
    points: int = 16,
    normals: Optional[_In] = None,
    views: Optional[_In] = None,
    candidates: Optional[Sequence[float]] = None,
    env_samples: int = 1,
    bsdf_samples: int = 1,
    max_width: int = 128,
) -> dict[str, Any]:
    """{"alpha", "bsdf_alphas": {bsdf: alpha}, "candidates": [{"alpha", "criterion",
    "per_bsdf": {bsdf: criterion}}], "width", "height", "seconds"}: criterion the geometric
    mean of exact variance of mis-balance-comp over mis-balance (< 1: compensation helps)."""

def compensated_map(map: EnvMap, alpha: float) -> EnvMap:
    """A new EnvMap over map's radiance, compensated with strength alpha >= 0."""
