// The docstrings of envmis._maps (python/envmis/_maps.pyi repeats the signatures).
// Measures and units are those of the C++ headers (envmap.h, binned.h, table.h).
#pragma once

namespace envmis::python::docs {

inline constexpr const char* kModule = R"(envmis maps, tables and sampling.

Units and measures throughout: directions are unit vectors (float32, x, y, z) in the
map's world frame (its `axes`, z up by default); pdfs are densities per steradian of
solid angle; radiance is linear RGB in the map's working colour space; image points uv
are in [0, 1)^2 with u along the columns (azimuth for equirect) and v down the rows
(v = 0 at the top, the +up pole). Arrays in may be any array-like of real numbers (NumPy
arrays of any integer or float dtype and strides, lists, tuples); the C++ library takes
float32, so other dtypes and strided views are converted into a float32 copy (a float64
value is rounded to float32: pass float32 to sample exactly what you hold), and a single
vector where (N, k) is expected counts as one row. Outputs (out=) are never converted:
they must be writeable C-contiguous float32 arrays of the exact shape. The version is
envmis.__version__.)";

inline constexpr const char* kImageError =
    "An image that cannot be read (missing, not an image, truncated, unknown colour space); "
    "the message names the file, as `envmis` prints it after 'envmis: '. An OSError.";
inline constexpr const char* kTableError =
    "A table file that cannot be read or written (missing, truncated, corrupted, another format or version); "
    "the message names the file. An OSError.";

inline constexpr const char* kSamples = R"(Samples(direction, pdf, radiance, uv): the result of sample() for N points.

direction: float32 (N, 3), unit vectors in the map's world frame.
pdf:       float32 (N,), the solid-angle density (per steradian) of drawing each direction;
           0 only at the poles of an equirect map, where the mapping degenerates.
radiance:  float32 (N, 3), linear RGB in the working space arriving from each direction
           (the texel's value: nearest, constant over the texel).
uv:        float32 (N, 2), the image points in [0, 1)^2 that the directions map from.
All are new C-contiguous arrays, bit-identical to the C++ single call EnvMap::sample.)";

inline constexpr const char* kEnvMap = R"(An importance-sampled environment map (envmis::EnvMap).

Samples directions with a density proportional to the texel's luminance L, or, when
compensated, to max(L - alpha Lbar, 0) (Lbar the solid-angle mean luminance), times the
texel's solid angle. Made by envmis.load() (an image or a table file), envmis.load_table()
or EnvMap(array). Immutable; sample, pdf and eval are vectorised over NumPy arrays and
release the GIL. Memory: 6 bytes a texel for the distribution plus 12 for the radiance
(none of its own where it maps a table file).)";

inline constexpr const char* kEnvMapInit = R"(A map of an array of pixels.

radiance: float32 (H, W, 3), linear RGB in `colorspace` (default: the working space),
    row 0 at the top (the +up pole for equirect). Copied into the map (H W 12 bytes),
    converted to `working_space` when `colorspace` differs (OpenColorIO); NaN, infinite
    and negative channel values are replaced by 0 and counted in stats["bad_pixels"].
compensate, alpha, axes, mapping, working_space: as envmis.load(); alpha defaults to 1.
The map's source is {"name": "array", "content_hash": hash64 of the array's bytes, ...}.
radiance of another dtype or strides is converted to float32 on the way (one more copy).
Raises ValueError for an array of another shape or of non-real values, an empty one, invalid options,
or pixels whose power overflows float32 (the message says by how much to scale them).
Cost: O(H W), parallel over rows.)";

inline constexpr const char* kCompensated = "True if the density is compensated (and no fallback replaced it).";
inline constexpr const char* kComplete =
    "True if pdf > 0 wherever the radiance is non-zero, so that the map alone estimates without bias. A "
    "compensated map is usually incomplete: combine it with BSDF sampling through MIS.";
inline constexpr const char* kOptions =
    "How the map was built: {'compensate': bool, 'alpha': float (the strength used, after 'auto'), 'axes': str "
    "('x,y,z' form), 'mapping': 'equirect' | 'equal-area', 'luma': (r, g, b) luminance weights of the working space}.";
inline constexpr const char* kStats =
    "What the build measured: {'bad_pixels': {'nan', 'infinite', 'negative'}: channel values replaced by 0, "
    "'mean_luminance': Lbar (solid-angle weighted), 'threshold': alpha Lbar if compensated else 0, "
    "'max_luminance', 'min_positive_luminance' (0 for a black map), 'zeroed_texels': texels with L > 0 that "
    "compensation set to density 0, 'fallback': 'none' | 'uncompensated' | 'uniform'}.";
inline constexpr const char* kSource =
    "Where the map came from, as its table file records it: {'name': the source image's file name (no folders), "
    "'content_hash': hash64 of its bytes (int), 'input_colorspace', 'working_colorspace', 'build_options': the "
    "options it was built with as `envmis precompute` spells them in its tables (save() records them with its own "
    "compact), '' where unknown (a binned table's plain map, an older table)}; empty strings and 0 for a map made "
    "outside this module.";
inline constexpr const char* kMapped =
    "True if the radiance is borrowed from a read-only memory mapping of a table file (load_table(mapped=True)).";
inline constexpr const char* kFromTable =
    "True if the map was read from a table file (load_table, or load of a table), mapped or copied. envmis.compare "
    "follows `envmis compare` on it: without compensation its default alpha is 0 (1 for a map built from an image).";
inline constexpr const char* kRadiance =
    "The repaired radiance, float32 (H, W, 3), linear RGB in the working space: a read-only view of the map's own "
    "pixels (or of its table file's mapping), no copy; its base keeps the map alive.";
inline constexpr const char* kDensity =
    "The image-space sampling density q(x, y) w_y (w_y = sin theta at the row's centre for equirect, 1 for "
    "equal-area), float32 (H, W), unnormalised, as the table file stores it. The map does not keep it (its buffer "
    "became the CDF): it is recomputed from the radiance on this Python object's first access (O(H W), 4 bytes a "
    "texel), then kept with the object; every access is a read-only view of that one array.";
inline constexpr const char* kSample = R"(Directions drawn from the map for N points.

u: float32 (N, 2), points in [0, 1)^2 (a random or low-discrepancy sequence;
   envmis.uniform_points gives what `envmis sample` draws). Every value must satisfy
   0 <= u < 1, else ValueError naming the first that does not, as in: u[12, 1] = 1 is
   outside [0, 1); NaN fails. Beware rng.random(...).astype(np.float32): float64 values at or
   above 1 - 2^-25 round to 1.0f; use envmis.uniform_points, rng.random(..., dtype=np.float32),
   or np.minimum(u, np.nextafter(np.float32(1), np.float32(0))). Returns Samples (direction,
   pdf per steradian, radiance, uv), bit-identical to N calls of the C++ EnvMap::sample,
   through the core's batch call sample_many (SIMD with AVX2). Cost: O(N), about the C++
   batch call's per sample (docs/performance.md), GIL released.
out: None (new arrays, N x 36 bytes), or a Samples of float32 C-contiguous writeable
   arrays of these shapes (an earlier call's) to write into and return. Reusing them matters at
   large N: writing fresh pages costs the kernel's page faults, which on a virtual machine
   can cost more than the sampling (docs/performance.md, "Python").)";
inline constexpr const char* kPdf = R"(The solid-angle pdf (per steradian) of sampling each direction.

directions: float32 (N, 3), unit vectors in the map's world frame. They are not
   normalised here (nor in C++): a vector of another length reads as another direction
   (its azimuth kept, its z taken as the cosine). Returns float32 (N,), bit-identical to
   Samples.pdf for the samples' own directions up to their float rounding; NaN for a
   direction that is not finite or is zero (NaN in, NaN out); O(N), GIL released.)";
inline constexpr const char* kEval =
    "The radiance arriving from each direction, float32 (N, 3) linear RGB in the working space (the nearest "
    "texel's). directions: float32 (N, 3) unit vectors in the world frame (not normalised); NaN for a direction "
    "that is not finite or is zero. O(N), GIL released.";
inline constexpr const char* kSave = R"(Writes the map as a table file (envmis::write_table).

compact=False stores the float32 density and radiance (16 bytes a texel; loads
bit-identical); compact=True the radiance in RGBE (4 bytes a texel; loads as the map of
the RGBE-rounded pixels). Written to a temporary file in the same folder and renamed
when complete: a failure leaves no partial table. Records the map's source and the
options it was built with as `envmis precompute` records them, so that a table saved
here from an image file is up to date for precompute's library mode with the same
options. Raises
TableError on I/O failure or a destination that is not a regular file.)";

inline constexpr const char* kBinned = R"(A normal-aware map (envmis::BinnedEnvMap): K bins of normals,
each with its own compensated density per lobe class, over a plain (uncompensated) map.

A shading point picks one of the four bins around its normal (world frame; for glossy
classes the mirror direction of the view) with a uniform `choice`, by bilinear weights
over the bins' centres, so that nothing changes in steps across bin borders; a lobe class
by its BSDF's sharpness (lobe_class). The same choice must serve a point's light samples
and its BSDF samples' MIS weights. Made by envmis.load(..., bins=K) or from a binned table. pdf and
sample speak solid angle (per steradian) over world directions, as EnvMap's.)";
inline constexpr const char* kPlain =
    "The plain map the bins are built over: an EnvMap sharing this map's radiance, its distribution rebuilt at each "
    "access (a binned map samples the plain density through its cells). Its source records what it is: the "
    "uncompensated map (compensate=0 ... bins=0), or no options for a binned table's.";
inline constexpr const char* kExponents = "The lobe classes' Phong exponents, ascending; 0 is diffuse (Lambert).";
inline constexpr const char* kLobeClass =
    "The lobe class of a BSDF with this Phong exponent (0 for Lambert): the nearest class on the scale "
    "log(1 + exponent). Raises ValueError for a negative or non-finite exponent.";
inline constexpr const char* kBinnedComplete =
    "True if every bin of lobe class `lobe` samples wherever its normals see light (no texel zeroed by compensation). "
    "Raises ValueError for a class the map does not have.";
inline constexpr const char* kBinnedSample = R"(Directions drawn for N (point, normal) pairs.

u: float32 (N, 2) in [0, 1)^2 (checked as EnvMap.sample checks it); normals: float32 (N, 3), the shading normals in the world
frame (or lobe axes); choices: float32 (N,) in [0, 1), each point's pick among the bins
around its normal; lobe: the lobe class (0 to classes - 1); view_cos: float32 (N,) in [0, 1], for a glossy
class each point's cosine of its view to its normal (C++ lobe_axis; default 1, head-on): a glossy bin seen
more obliquely than its limit samples the plain density. Returns Samples as EnvMap.sample does, bit-identical to N single calls
of the C++ BinnedEnvMapView::sample; out as EnvMap.sample's; NaN throughout for a normal that is not
finite or is zero (NaN in, NaN out). O(N), GIL released.)";
inline constexpr const char* kBinnedPdf = R"(The solid-angle pdf (per steradian) of each direction under the bin
its normal and choice pick (lobe class `lobe`): what sample() with them would have drawn.

directions, normals: float32 (N, 3), world frame; directions unit length (not
normalised); choices: float32 (N,) in [0, 1); view_cos as sample()'s. Returns float32 (N,), NaN where a direction or
normal is not finite or is zero. O(N), GIL released.)";

inline constexpr const char* kLoad = R"(Loads an HDR image (or a table file) as `envmis precompute` builds it.

path: an image that OpenImageIO reads (EXR, .hdr, .pfm, TIFF...), converted with
   OpenColorIO from `colorspace` (default: the file's metadata) to `working_space`; or a
   table file (recognised by its magic), whose own recorded options are used: the keywords
   are then ignored, as the command ignores its flags for a table.
compensate: compensate the density for MIS (False: luminance times solid angle).
alpha: compensation strength, a number >= 0, or the str "auto" (choose_alpha: the
   candidate with the lowest exact variance of balance MIS); any other str is refused. Default: 1, or with bins auto per bin and lobe class.
axes: the world frame of directions: "z-up", "y-up", a renderer's ("pbrt-v4", "mitsuba3", "blender") or a signed permutation like "x,z,-y".
mapping: "equirect" (latitude-longitude) or "equal-area" (octahedral, a square image).
bins: K = g^2 (g 1 to 64) gives a BinnedEnvMap as `precompute --bins K` builds it;
   cell_columns its cell grid's columns (0: width / 32), bin_cost what a compensated bin's
   estimate costs over a plain one (1 to 100; `precompute --bin-cost`).
Returns EnvMap or BinnedEnvMap. The loader's notes (a square equirect image, an OpenEXR
data window) are issued as UserWarning. Raises ImageError (the file), TableError (a
corrupt table), ValueError (invalid options; a map whose power overflows float32), with
the messages `envmis` prints. GIL released while loading and building (O(W H)).)";
inline constexpr const char* kLoadTable = R"(Reads a table file written by EnvMap.save or `envmis precompute`.

mapped=True borrows a full table's radiance from a read-only memory mapping of the file
(no copy, pages shared with other processes; EnvMap.mapped says whether it did);
mapped=False reads it into memory. Either way the map samples bit-identically to the one
saved. Returns EnvMap, or BinnedEnvMap for a binned table. Raises TableError naming the
file if it is missing, truncated, corrupted, of another format or version.)";
inline constexpr const char* kUniformPoints = R"(The n points in [0, 1)^2 that `envmis sample -n n --seed seed` draws.

float32 (n, 2): a mt19937_64 seeded with `seed`, 24 random bits per coordinate (the float
grid k / 2^24), u then v per point; so map.sample(uniform_points(n, seed)) equals the
command's CSV bit for bit. O(n).)";
inline constexpr const char* kTimeSampleMany = R"(Benchmark helper: the median wall time in seconds over `repeats`
runs of the C++ batch call sample_many on u (its columns as separate arrays, image points
included), measured inside C++: the reference for EnvMap.sample's cost
(scripts/python_bench.py). Outputs preallocated and touched once before timing, or with
fresh_outputs newly allocated in each run, their page faults timed (as a new NumPy
array's are).)";

}  // namespace envmis::python::docs
