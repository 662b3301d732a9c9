// Specification of table files (table.h, docs/table-format.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "envmis/hash.h"
#include "envmis/table.h"
#include "maps.h"
#include "stats.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;

class TableTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("envmis_table_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path saved_table() {
        EnvMapOptions o;
        o.compensation.alpha = 0.75f;
        o.axes = Axes::parse("y-up");
        map_ = EnvMap(test::sun_sky_map(96, 48), o);
        const fs::path path = dir_ / "sky.envmis";
        write_table(path, map_, source_);
        return path;
    }
    static std::vector<char> bytes_of(const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), {}};
    }
    static void write_bytes(const fs::path& p, const std::vector<char>& bytes) {
        std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    // Expects read_table to throw a TableError whose message names the file and contains `problem`.
    static void expect_rejected(const fs::path& p, const std::string& problem) {
        try {
            read_table(p);
            ADD_FAILURE() << p << " was accepted; expected: " << problem;
        } catch (const TableError& e) {
            EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
        }
    }

    fs::path dir_;
    EnvMap map_;
    TableSource source_{"sky.exr", 0x1234abcd5678ef90ull, "lin_rec709", "ACEScg"};
};

// `loaded` samples exactly as `expected`: every field of n samples, bit for bit, and
// the pdf of each sampled direction.
void expect_identical_samples(const EnvMap& expected, const EnvMap& loaded, uint64_t seed, int n) {
    test::Rng rng(seed);
    for (int i = 0; i < n; ++i) {
        const Vec2 u = rng.uniform2();
        const EnvSample a = expected.sample(u), b = loaded.sample(u);
        ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "sample " << i;
        ASSERT_EQ(expected.pdf(a.direction), loaded.pdf(a.direction));
    }
}

TEST_F(TableTest, RoundTripGivesBitIdenticalSamples) {
    const Table t = read_table(saved_table());
    expect_identical_samples(map_, t.map, 1, 100000);
}

TEST_F(TableTest, RoundTripKeepsOptionsStatsAndSource) {
    const Table t = read_table(saved_table());
    EXPECT_EQ(t.source.name, source_.name);
    EXPECT_EQ(t.source.content_hash, source_.content_hash);
    EXPECT_EQ(t.source.input_colorspace, source_.input_colorspace);
    EXPECT_EQ(t.source.working_colorspace, source_.working_colorspace);
    EXPECT_EQ(t.map.options().compensation.alpha, 0.75f);
    EXPECT_TRUE(t.map.options().compensation.enabled);
    EXPECT_EQ(t.map.options().axes, Axes::parse("y-up"));
    EXPECT_EQ(t.map.stats().mean_luminance, map_.stats().mean_luminance);
    EXPECT_EQ(t.map.stats().zeroed_texels, map_.stats().zeroed_texels);
    EXPECT_EQ(t.map.stats().threshold, map_.stats().threshold);
    EXPECT_EQ(t.map.compensated(), map_.compensated());
    EXPECT_EQ(t.map.complete(), map_.complete());
}

TEST_F(TableTest, EveryCorruptedByteIsDetected) {
    const fs::path path = saved_table();
    const std::vector<char> good = bytes_of(path);
    // Flip one bit at a spread of offsets through preamble, metadata and payload.
    for (size_t offset = 0; offset < good.size(); offset += good.size() / 97 + 1) {
        std::vector<char> bad = good;
        bad[offset] ^= 0x10;
        write_bytes(path, bad);
        EXPECT_THROW(read_table(path), TableError) << "offset " << offset;
    }
}

TEST_F(TableTest, CorruptedPayloadIsNamedAsSuch) {
    const fs::path path = saved_table();
    std::vector<char> bytes = bytes_of(path);
    bytes[bytes.size() - 100] ^= 1;
    write_bytes(path, bytes);
    expect_rejected(path, "corrupted payload");
}

TEST_F(TableTest, TruncatedFilesAreRejected) {
    const fs::path path = saved_table();
    const std::vector<char> good = bytes_of(path);
    for (size_t size : {size_t{0}, size_t{5}, size_t{20}, size_t{40}, good.size() / 2, good.size() - 1}) {
        write_bytes(path, {good.begin(), good.begin() + static_cast<std::ptrdiff_t>(size)});
        EXPECT_THROW(read_table(path), TableError) << size;
    }
    write_bytes(path, {good.begin(), good.begin() + static_cast<std::ptrdiff_t>(good.size() / 2)});
    expect_rejected(path, "truncated");
}

TEST_F(TableTest, ForeignFilesAreRejected) {
    const fs::path path = dir_ / "foreign.envmis";
    write_bytes(path, {'#', '?', 'R', 'A', 'D', 'I', 'A', 'N', 'C', 'E', '\n'});
    expect_rejected(path, "not an envmis table");
    expect_rejected(dir_ / "missing.envmis", "no such file");
    expect_rejected(dir_, "not a regular file");
}

// A compact table stores RGBE radiance (4 bytes a texel) and loads as the map built
// from the RGBE-rounded radiance, bit for bit; damage is still caught.
TEST_F(TableTest, CompactTablesHoldTheRoundedMap) {
    EnvMapOptions o;
    o.compensation.alpha = 0.75f;
    RgbImage image = test::random_map(96, 48, 11, 8);
    image.pixels[5] = {NAN, 1, 2};  // repaired and counted by the map; the count is kept
    const EnvMap map(image, o);
    const fs::path path = dir_ / "compact.envmis";
    write_table(path, map, source_, TableEncoding::compact);
    const fs::path full = dir_ / "full.envmis";
    write_table(full, map, source_);
    EXPECT_EQ(fs::file_size(full) - fs::file_size(path), 96u * 48 * 12);

    const Table loaded = read_table(path);
    const EnvMap rounded(rgbe_round(map.radiance()), o);
    EXPECT_EQ(loaded.map.stats().bad_pixels.nan, 1u);
    EXPECT_EQ(loaded.map.stats().threshold, rounded.stats().threshold);
    expect_identical_samples(rounded, loaded.map, 12, 10000);

    std::vector<char> bytes = bytes_of(path);
    bytes[bytes.size() - 20] ^= 0x10;
    write_bytes(path, bytes);
    expect_rejected(path, "corrupted payload");
}

// RGBE keeps each pixel's largest channel within half a step of its 8-bit mantissa
// (0.4%), the others within half a step of the largest's scale; black stays black.
TEST(Rgbe, RoundingErrorIsBounded) {
    test::Rng rng(13);
    RgbImage image{1000, 1, {}};
    for (int i = 0; i < 1000; ++i) {
        const float scale = std::pow(10.0f, 16 * rng.uniform() - 8);
        image.pixels.push_back({scale * rng.uniform(), scale * rng.uniform(), scale * rng.uniform()});
    }
    image.pixels[0] = {0, 0, 0};
    image.pixels[1] = {1.6e38f, 1, 0};  // the largest RGBE represents
    const RgbImage rounded = rgbe_round(image);
    EXPECT_EQ(rounded.pixels[0].r, 0.0f);
    EXPECT_GT(rgbe_round({1, 1, {{3e38f, 0, 0}}}).pixels[0].r, 1.6e38f);  // saturates, never wraps to black
    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const Rgb a = image.pixels[i], b = rounded.pixels[i];
        const float m = std::max({a.r, a.g, a.b});
        for (auto [x, y] : {std::pair{a.r, b.r}, std::pair{a.g, b.g}, std::pair{a.b, b.b}}) {
            ASSERT_TRUE(std::isfinite(y)) << i;
            ASSERT_LE(std::abs(x - y), m / 255) << i;  // half a step of 2^e / 256 with m >= 2^(e-1)
        }
        const float bm = std::max({b.r, b.g, b.b});
        ASSERT_LE(std::abs(bm - m), m / 256) << i;
    }
}

TEST_F(TableTest, EqualAreaTablesRoundTrip) {
    EnvMapOptions o;
    o.mapping = Mapping::equal_area;
    const EnvMap map(test::sun_sky_map(48, 48), o);
    const fs::path path = dir_ / "square.envmis";
    write_table(path, map, source_);
    const Table loaded = read_table(path);
    EXPECT_EQ(loaded.map.options().mapping, Mapping::equal_area);
    expect_identical_samples(map, loaded.map, 9, 10000);
}

// Version 1 had a reserved zero byte where version 2 keeps the mapping: such files are
// equirectangular and still read; a version 1 file with another byte there is corrupt.
TEST_F(TableTest, VersionOneTablesStillRead) {
    const fs::path path = saved_table();
    std::vector<char> bytes = bytes_of(path);
    const uint32_t one = 1, preamble = 32;
    uint32_t m = 0;  // metadata size
    std::memcpy(&m, bytes.data() + 24, sizeof m);
    std::memcpy(bytes.data() + 8, &one, sizeof one);
    const size_t mapping_byte = preamble + 5 * 4 + 3 * 4 + 3;  // after size, kind, flags, alpha, luma, axes
    ASSERT_EQ(bytes[mapping_byte], 1);                          // equirect, as version 2 writes it
    const auto reseal = [&] {
        const uint64_t digest = hash64(std::as_bytes(std::span(bytes.data(), preamble + m)));
        std::memcpy(bytes.data() + preamble + m, &digest, sizeof digest);
        write_bytes(path, bytes);
    };
    bytes[mapping_byte] = 0;
    reseal();
    const Table loaded = read_table(path);
    EXPECT_EQ(loaded.map.options().mapping, Mapping::equirect);
    EXPECT_EQ(loaded.map.sample({0.3f, 0.6f}).pdf, map_.sample({0.3f, 0.6f}).pdf);
    bytes[mapping_byte] = 2;
    reseal();
    expect_rejected(path, "unknown mapping");
}

TEST_F(TableTest, NewerVersionsAreRejectedWithAnUpgradeHint) {
    const fs::path path = saved_table();
    std::vector<char> bytes = bytes_of(path);
    const uint32_t newer = kTableVersion + 1;
    std::memcpy(bytes.data() + 8, &newer, sizeof newer);
    write_bytes(path, bytes);
    expect_rejected(path, "newer than this envmis reads");
}

TEST_F(TableTest, ImplausibleSizesAreRejectedBeforeAllocating) {
    const fs::path path = saved_table();
    std::vector<char> bytes = bytes_of(path);
    const uint64_t huge = uint64_t{1} << 62;
    std::memcpy(bytes.data() + 16, &huge, sizeof huge);  // total file size
    write_bytes(path, bytes);
    expect_rejected(path, "truncated");
    bytes = bytes_of(saved_table());
    const uint32_t big = 1u << 30;
    std::memcpy(bytes.data() + 24, &big, sizeof big);  // metadata size
    write_bytes(path, bytes);
    expect_rejected(path, "too large");
}

TEST_F(TableTest, WritingIsAtomic) {
    const fs::path path = saved_table();
    const auto before = bytes_of(path);
    // A destination in a missing folder fails, leaving nothing behind.
    EXPECT_THROW(write_table(dir_ / "missing" / "x.envmis", map_, source_), TableError);
    EXPECT_FALSE(fs::exists(dir_ / "missing"));
    // Overwriting replaces the file whole and leaves no temporary file.
    write_table(path, EnvMap(test::constant_map(8, 4, {1, 2, 3})), source_);
    EXPECT_NE(bytes_of(path).size(), before.size());
    size_t files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
    EXPECT_EQ(files, 1u);
}

TEST(TableParse, InMemoryBytesGiveTheSameErrors) {
    const std::vector<std::byte> empty;
    EXPECT_THROW(parse_table(empty, "mem"), TableError);
    const std::vector<std::byte> junk(100, std::byte{0x89});
    EXPECT_THROW(parse_table(junk, "mem"), TableError);
}

}  // namespace
}  // namespace envmis
