// Acceptance test: `envmis sample` output follows the documented distribution exactly,
// for every map in the shared test set (../shared/data/envmaps) and the bundled maps
// (data/envmaps), compensated and not.
//
// The documented distribution, which this file computes on its own from the image file
// (read here with OpenImageIO, all arithmetic in double, nothing from envmis's library):
//   - equirectangular, v = 0 the top row: theta = pi v, phi = 2 pi u,
//     direction = (sin theta cos phi, sin theta sin phi, cos theta) (z up);
//   - L = 0.2126 R + 0.7152 G + 0.0722 B after NaN, Inf and negative channels become 0;
//   - texel (i, j) has image-space mass proportional to q_ij sin(theta_j), theta_j at
//     the row centre pi (j + 0.5) / H, with q = L (--no-compensate) or
//     q = max(L - Lbar, 0) (default, alpha = 1), Lbar the solid-angle mean
//     sum_j sin(theta_j) sum_i L_ij / (W sum_j sin(theta_j)); if q is 0 everywhere the
//     uncompensated density is used (and a black map is uniform over the sphere);
//   - the point is uniform within its texel; the solid-angle pdf is the texel's image
//     density W H mass / sum(mass) divided by 2 pi^2 sin(theta), theta the sample's own.
//
// For each map and mode the CLI draws N samples to a CSV, and the test checks
//   (a) every row's direction against the formula from its (u, v),
//   (b) every row's pdf against the formula for the texel holding (u, v),
//   (c) the texel counts against the masses, by a chi-square test (see goodness_of_fit),
//       at a Sidak-corrected level so that the whole family of map x mode tests has a
//       1% chance of a false alarm on a correct build,
//   (d) that no sample lies in a texel of zero mass.
// SampleCheck.GoodnessOfFitRejectsPlausibleMistakes shows that (c) alone has the power
// to reject plausible mistakes in a reference.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <string>
#include <vector>

#include "cli_run.h"
#include "stats.h"

namespace {

namespace fs = std::filesystem;
using envmis::test::chi_square;
using envmis::test::ChiSquare;
using envmis::test::quoted;
using envmis::test::read_file;
using envmis::test::sidak_level;

constexpr double kPi = 3.14159265358979323846;

// Samples per map and mode: enough for the bright texels and 16x16 bins to expect many
// samples each, few enough that 28 cases take well under a minute on two cores.
constexpr uint64_t kSamples = 400'000;
constexpr double kFamilyLevel = 0.01;
constexpr uint32_t kBinSize = 16;          // texels per side of a coarse chi-square bin
constexpr size_t kMaxSingleTexels = 1024;  // brightest texels tested one by one...
constexpr double kMinSingleExpected = 25;  // ...if each expects at least this many samples

// ---------------------------------------------------------------------------------
// The documented distribution, from the image file alone.

// The rules that define the masses. Only the defaults are the documented ones; the
// others are mistakes the goodness-of-fit test must catch (see the last test).
struct Rules {
    std::array<double, 3> luma = {0.2126, 0.7152, 0.0722};
    bool solid_angle_mean = true;  // Lbar weighted by sin(theta), not a per-texel mean
    bool sin_theta = true;         // mass = q sin(theta_j), not q
};

struct Luminance {
    uint32_t w = 0, h = 0;
    std::vector<double> values;  // row-major, row 0 at the top
};

Luminance read_luminance(const fs::path& path, const Rules& rules) {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw std::runtime_error("test setup: cannot open " + path.string() + ": " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.nchannels < 3) throw std::runtime_error("test setup: " + path.string() + " is not RGB");
    Luminance l{static_cast<uint32_t>(spec.width), static_cast<uint32_t>(spec.height), {}};
    std::vector<float> rgb(size_t{l.w} * l.h * 3);
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, rgb.data()))
        throw std::runtime_error("test setup: cannot read " + path.string() + ": " + in->geterror());
    l.values.resize(size_t{l.w} * l.h);
    for (size_t t = 0; t < l.values.size(); ++t) {
        double sum = 0;
        for (int c = 0; c < 3; ++c) {
            const float v = rgb[3 * t + c];
            sum += rules.luma[c] * (std::isfinite(v) && v > 0 ? v : 0.0);
        }
        l.values[t] = sum;
    }
    return l;
}

double row_sin_theta(uint32_t y, uint32_t h) { return std::sin(kPi * (y + 0.5) / h); }

// Texel probabilities, with what the pdf check needs to know about each.
struct Reference {
    uint32_t w = 0, h = 0;
    std::vector<double> mass;      // per texel, summing to 1
    std::vector<double> row_mass;  // per row, summing to 1
    // Relative error of a texel's mass that float arithmetic in q = L - Lbar may cause:
    // large only for texels just above the threshold, which carry almost no mass.
    std::vector<double> float_error;

    size_t texel(uint32_t x, uint32_t y) const { return size_t{y} * w + x; }
};

Reference reference_distribution(const Luminance& l, bool compensated, const Rules& rules) {
    Reference r{l.w, l.h, std::vector<double>(l.values.size()), std::vector<double>(l.h), {}};
    double weighted = 0, weights = 0, plain = 0;
    for (uint32_t y = 0; y < l.h; ++y) {
        double row = 0;
        for (uint32_t x = 0; x < l.w; ++x) row += l.values[r.texel(x, y)];
        weighted += row_sin_theta(y, l.h) * row;
        weights += row_sin_theta(y, l.h);
        plain += row;
    }
    const double lbar = rules.solid_angle_mean ? weighted / (l.w * weights) : plain / l.values.size();

    auto fill = [&](auto&& q_of) {
        double total = 0;
        for (uint32_t y = 0; y < l.h; ++y)
            for (uint32_t x = 0; x < l.w; ++x)
                total += r.mass[r.texel(x, y)] =
                    q_of(l.values[r.texel(x, y)]) * (rules.sin_theta ? row_sin_theta(y, l.h) : 1.0);
        return total;
    };
    double total = compensated ? fill([&](double v) { return std::max(v - lbar, 0.0); }) : 0.0;
    const double threshold = total > 0 ? lbar : 0.0;  // no compensation once it zeroes everything
    if (!(total > 0)) total = fill([](double v) { return v; });
    if (!(total > 0)) total = fill([](double) { return 1.0; });  // black: uniform over the sphere

    r.float_error.resize(r.mass.size());
    for (size_t t = 0; t < r.mass.size(); ++t) {
        r.mass[t] /= total;
        r.row_mass[t / l.w] += r.mass[t];
        const double q = l.values[t] - threshold;
        r.float_error[t] = q > 0 ? 0x1p-21 * (l.values[t] + threshold) / q : 0.0;
    }
    return r;
}

// ---------------------------------------------------------------------------------
// The CLI's output.

struct Row {
    float u, v, x, y, z, pdf;
};

// Reads `u,v,x,y,z,pdf` rows; throws on anything else, so that a malformed file fails loudly.
std::vector<Row> read_csv(const fs::path& path) {
    const std::string text = read_file(path);
    const std::string header = "u,v,x,y,z,pdf\n";
    if (text.compare(0, header.size(), header) != 0) throw std::runtime_error(path.string() + ": wrong header");
    std::vector<Row> rows;
    const char* p = text.data() + header.size();
    const char* end = text.data() + text.size();
    while (p < end) {
        float f[6];
        for (int k = 0; k < 6; ++k) {
            const auto [next, ec] = std::from_chars(p, end, f[k]);
            const char expected = k < 5 ? ',' : '\n';
            if (ec != std::errc() || next == end || *next != expected)
                throw std::runtime_error(path.string() + ": malformed row " + std::to_string(rows.size() + 1));
            p = next + 1;
        }
        rows.push_back({f[0], f[1], f[2], f[3], f[4], f[5]});
    }
    return rows;
}

// Runs `envmis sample` into `csv`; returns an empty string or what went wrong.
std::string run_sample(const fs::path& map, bool compensated, uint64_t seed, const fs::path& csv) {
    const fs::path err = csv.string() + ".stderr";
    const std::string command = quoted(ENVMIS_CLI) + " sample " + quoted(map.string()) + " -n " +
                                std::to_string(kSamples) + " --seed " + std::to_string(seed) +
                                (compensated ? "" : " --no-compensate") + " -o " + quoted(csv.string()) + " 2> " +
                                quoted(err.string());
    const int status = std::system(command.c_str());
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return {};
    return command + " failed (status " + std::to_string(status) + "): " + read_file(err);
}

// ---------------------------------------------------------------------------------
// The checks.

std::string str(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.9g", v);
    return buffer;
}

// Keeps the count of failures and the first few, for a readable message; `describe`
// is called for those few only, since formatting every failing row of a badly wrong
// distribution would take seconds.
struct Failures {
    uint64_t count = 0;
    std::string examples;

    template <class Describe>
    void add(size_t row, Describe&& describe) {
        if (++count <= 5) examples += "\n  row " + std::to_string(row + 1) + ": " + describe();
    }
    std::string describe(const char* check) const {
        return std::to_string(count) + " rows fail " + check + ", e.g." + examples;
    }
};

struct RowChecks {
    Failures range, direction, pdf, zero_mass;
    double worst_pdf_excess = 0;  // largest |pdf - expected| / tolerance
    std::vector<double> counts;   // samples per texel
};

// Checks (a), (b) and (d) on every row, and counts the samples per texel for (c).
RowChecks check_rows(const std::vector<Row>& rows, const Reference& ref) {
    RowChecks c;
    c.counts.assign(ref.mass.size(), 0);
    for (size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        const auto row_text = [&r] {
            return "u=" + str(r.u) + " v=" + str(r.v) + " direction=(" + str(r.x) + ", " + str(r.y) + ", " + str(r.z) +
                   ") pdf=" + str(r.pdf);
        };
        if (!(r.u >= 0 && r.u < 1 && r.v >= 0 && r.v < 1)) {
            c.range.add(i, [&] { return row_text() + ": (u, v) outside [0,1)^2"; });
            continue;
        }
        // (a) The direction of the documented mapping; float output, so 1e-5 absolute.
        const double theta = kPi * r.v, phi = 2 * kPi * r.u;
        const double d[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
        if (std::abs(r.x - d[0]) > 1e-5 || std::abs(r.y - d[1]) > 1e-5 || std::abs(r.z - d[2]) > 1e-5)
            c.direction.add(i, [&] {
                return row_text() + ": expected direction (" + str(d[0]) + ", " + str(d[1]) + ", " + str(d[2]) + ")";
            });

        // The exact texel: u * W is exact in double for a float u.
        const auto x = std::min(static_cast<uint32_t>(double{r.u} * ref.w), ref.w - 1);
        const auto y = std::min(static_cast<uint32_t>(double{r.v} * ref.h), ref.h - 1);
        const size_t t = ref.texel(x, y);
        const auto texel_text = [&] { return " (texel " + std::to_string(x) + ", " + std::to_string(y) + ")"; };
        c.counts[t] += 1;
        // (d) A texel of zero mass is never sampled.
        if (ref.mass[t] == 0) {
            c.zero_mass.add(i, [&] { return row_text() + ": zero mass" + texel_text(); });
            continue;
        }
        // (b) The pdf: relative 1e-4, plus the library's documented precision: row and
        // column probabilities are each stored in 31-bit fixed point (error <= 2^-31), so
        // the texel's probability may be off by 2^-31 (row + column probability); plus
        // the float rounding of q near the compensation threshold.
        const double sin_theta = std::sin(theta);
        const double to_solid_angle = static_cast<double>(ref.w) * ref.h / (2 * kPi * kPi * sin_theta);
        const double expected = ref.mass[t] * to_solid_angle;
        const double column = ref.mass[t] / ref.row_mass[y];
        const double tolerance = expected * (1e-4 + ref.float_error[t]) +
                                 1.01 * 0x1p-31 * (ref.row_mass[y] + column + 0x1p-31) * to_solid_angle;
        const double error = std::abs(r.pdf - expected);
        c.worst_pdf_excess = std::max(c.worst_pdf_excess, error / tolerance);
        if (!(error <= tolerance))
            c.pdf.add(i, [&] {
                return row_text() + ": expected pdf " + str(expected) + " +- " + str(tolerance) + ", relative error " +
                       str(error / expected) + texel_text();
            });
    }
    return c;
}

// (c) Pearson's test of the texel counts against the masses. 512K texels cannot each be
// a cell, so the brightest texels (which hold most of the mass on sunny maps, and all of
// it after compensation on some) are cells of their own, and the rest are pooled in
// square bins of kBinSize texels; chi_square() pools bins expecting fewer than 5.
ChiSquare goodness_of_fit(const std::vector<double>& counts, const Reference& ref, uint64_t n) {
    std::vector<size_t> order(ref.mass.size());
    std::iota(order.begin(), order.end(), size_t{0});
    const size_t singles = std::min(kMaxSingleTexels, order.size());
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(singles), order.end(),
                      [&](size_t a, size_t b) { return ref.mass[a] > ref.mass[b]; });

    std::vector<double> expected, observed;
    std::vector<bool> single(ref.mass.size(), false);
    for (size_t k = 0; k < singles && ref.mass[order[k]] * n >= kMinSingleExpected; ++k) {
        single[order[k]] = true;
        expected.push_back(ref.mass[order[k]] * n);
        observed.push_back(counts[order[k]]);
    }
    const uint32_t bins_x = (ref.w + kBinSize - 1) / kBinSize, bins_y = (ref.h + kBinSize - 1) / kBinSize;
    const size_t first_bin = expected.size();
    expected.resize(first_bin + size_t{bins_x} * bins_y, 0.0);
    observed.resize(expected.size(), 0.0);
    for (uint32_t y = 0; y < ref.h; ++y)
        for (uint32_t x = 0; x < ref.w; ++x) {
            const size_t t = ref.texel(x, y);
            if (single[t]) continue;
            const size_t bin = first_bin + size_t{y / kBinSize} * bins_x + x / kBinSize;
            expected[bin] += ref.mass[t] * n;
            observed[bin] += counts[t];
        }
    return chi_square(expected, observed);
}

// ---------------------------------------------------------------------------------
// The maps and modes.

struct Case {
    std::string name;  // for the test's name: file name and mode, alphanumerics and _
    fs::path map;
    bool compensated = true;
};

void PrintTo(const Case& c, std::ostream* os) {
    *os << c.map.filename().string() << (c.compensated ? " compensated" : " --no-compensate");
}

std::vector<fs::path> maps_in(const fs::path& folder) {
    std::vector<fs::path> maps;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec))
        if (entry.path().extension() == ".exr" || entry.path().extension() == ".hdr") maps.push_back(entry.path());
    std::sort(maps.begin(), maps.end());
    return maps;
}

bool same_bytes(const fs::path& a, const fs::path& b) {
    std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
    return std::equal(std::istreambuf_iterator<char>(fa), std::istreambuf_iterator<char>(),
                      std::istreambuf_iterator<char>(fb), std::istreambuf_iterator<char>());
}

// The bundled maps, so the test runs in a bare clone, and the shared ones; a shared map
// that is byte-identical to a bundled one is tested once.
const std::vector<Case>& all_cases() {
    static const std::vector<Case> cases = [] {
        std::vector<fs::path> maps = maps_in(fs::path(ENVMIS_DATA_DIR) / "envmaps");
        const size_t bundled = maps.size();
        for (const fs::path& shared : maps_in(ENVMIS_SHARED_MAPS)) {
            const bool duplicate = std::any_of(
                maps.begin(), maps.begin() + static_cast<std::ptrdiff_t>(bundled),
                [&](const fs::path& b) { return b.filename() == shared.filename() && same_bytes(b, shared); });
            if (!duplicate) maps.push_back(shared);
        }
        std::vector<Case> cases;
        for (size_t i = 0; i < maps.size(); ++i)
            for (bool compensated : {true, false}) {
                std::string name = (i >= bundled ? "shared_" : "bundled_") + maps[i].filename().string();
                for (char& ch : name)
                    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                cases.push_back({name + (compensated ? "_compensated" : "_uncompensated"), maps[i], compensated});
            }
        return cases;
    }();
    return cases;
}

// A temporary folder per test, removed at the end.
struct ScratchFolder {
    fs::path path;
    explicit ScratchFolder(const std::string& name)
        : path(fs::temp_directory_path() / ("envmis_sample_check_" + std::to_string(::getpid()) + "_" + name)) {
        fs::create_directories(path);
    }
    ~ScratchFolder() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};

struct Sampled {
    std::vector<Row> rows;
    std::string error;
};

Sampled sample_with_cli(const Case& c) {
    ScratchFolder scratch(c.name);
    const fs::path csv = scratch.path / "samples.csv";
    Sampled s;
    s.error = run_sample(c.map, c.compensated, c.compensated ? 20251 : 20252, csv);
    if (s.error.empty()) s.rows = read_csv(csv);
    return s;
}

class SampleFollowsTheDocumentedDistribution : public testing::TestWithParam<Case> {};

TEST_P(SampleFollowsTheDocumentedDistribution, DirectionsPdfsAndFrequencies) {
    const Case& c = GetParam();
    const Sampled sampled = sample_with_cli(c);
    ASSERT_EQ(sampled.error, "");
    ASSERT_EQ(sampled.rows.size(), kSamples);

    const Reference ref = reference_distribution(read_luminance(c.map, {}), c.compensated, {});
    const RowChecks checks = check_rows(sampled.rows, ref);
    EXPECT_EQ(checks.range.count, 0u) << checks.range.describe("(u, v) in [0,1)^2");
    EXPECT_EQ(checks.direction.count, 0u) << checks.direction.describe("(a) direction of (u, v)");
    EXPECT_EQ(checks.pdf.count, 0u) << checks.pdf.describe("(b) pdf of the texel") << "\n  largest error "
                                    << checks.worst_pdf_excess << " times the tolerance";
    EXPECT_EQ(checks.zero_mass.count, 0u) << checks.zero_mass.describe("(d) no sample in a zero-mass texel");

    const double level = sidak_level(kFamilyLevel, static_cast<int>(all_cases().size()));
    const ChiSquare fit = goodness_of_fit(checks.counts, ref, sampled.rows.size());
    RecordProperty("chi_square", fit.describe());
    EXPECT_GT(fit.p_value, level) << "(c) texel counts do not follow the masses: " << fit.describe();
}

INSTANTIATE_TEST_SUITE_P(Maps, SampleFollowsTheDocumentedDistribution, testing::ValuesIn(all_cases()),
                         [](const testing::TestParamInfo<Case>& info) { return info.param.name; });

// The goodness-of-fit test alone (without the exact pdf check, which catches these at
// once) has the power to reject a reference with a plausible mistake, on a bundled
// sunny map with compensation: equal luminance weights, Lbar as a per-texel mean instead
// of the solid-angle mean, or masses without sin(theta).
TEST(SampleCheck, GoodnessOfFitRejectsPlausibleMistakes) {
    const Case c{"power", fs::path(ENVMIS_DATA_DIR) / "envmaps" / "city.exr", true};
    const Sampled sampled = sample_with_cli(c);
    ASSERT_EQ(sampled.error, "");
    struct Mistake {
        const char* key;  // for the XML report
        const char* description;
        Rules rules;
    };
    const Mistake mistakes[] = {
        {"equal_luma", "luminance weights (1/3, 1/3, 1/3)", Rules{.luma = {1.0 / 3, 1.0 / 3, 1.0 / 3}}},
        {"per_texel_mean", "Lbar as the per-texel mean", Rules{.solid_angle_mean = false}},
        {"no_sin_theta", "masses without sin(theta)", Rules{.sin_theta = false}}};
    const double level = sidak_level(kFamilyLevel, static_cast<int>(all_cases().size()));
    for (const Mistake& m : mistakes) {
        const Reference wrong = reference_distribution(read_luminance(c.map, m.rules), c.compensated, m.rules);
        const ChiSquare fit = goodness_of_fit(check_rows(sampled.rows, wrong).counts, wrong, sampled.rows.size());
        RecordProperty(m.key, fit.describe());
        EXPECT_LT(fit.p_value, level) << m.description << ": " << fit.describe();
    }
}

// The whole shared set is tested when it is there; a missing file would otherwise shrink
// the acceptance test silently.
TEST(SampleCheck, CoversTheWholeSharedMapSet) {
    if (!fs::is_directory(ENVMIS_SHARED_MAPS)) GTEST_SKIP() << ENVMIS_SHARED_MAPS << " does not exist";
    EXPECT_EQ(maps_in(ENVMIS_SHARED_MAPS).size(), 14u);
}

}  // namespace
