// Specification of table files (table.h, docs/table-format.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/build/table_writer.h"
#include "envmis/math/hash.h"
#include "envmis/table/table.h"
#include "maps.h"
#include "stats.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;

class TableTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() /
               ("envmis_table_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    fs::path saved_table() {
        EnvMapOptions o;
        o.compensation.alpha = 0.75f;
        o.axes = Axes::parse("y-up");
        map_ = build_env_map(test::sun_sky_map(96, 48), o);
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
    TableSource source_{"sky.exr", 0x1234abcd5678ef90ull, "lin_rec709", "ACEScg", "compensate=1 alpha=0.75"};
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
    EXPECT_EQ(t.source.build_options, source_.build_options);
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
    const EnvMap map = build_env_map(image, o);
    const fs::path path = dir_ / "compact.envmis";
    write_table(path, map, source_, TableEncoding::compact);
    const fs::path full = dir_ / "full.envmis";
    write_table(full, map, source_);
    EXPECT_EQ(fs::file_size(full) - fs::file_size(path), 96u * 48 * 12);

    const Table loaded = read_table(path);
    const EnvMap rounded = build_env_map(rgbe_round(map.radiance()), o);
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
    EXPECT_GT(rgbe_round(RgbImage{1, 1, {{3e38f, 0, 0}}}).pixels[0].r, 1.6e38f);  // saturates, never wraps to black
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
    const EnvMap map = build_env_map(test::sun_sky_map(48, 48), o);
    const fs::path path = dir_ / "square.envmis";
    write_table(path, map, source_);
    const Table loaded = read_table(path);
    EXPECT_EQ(loaded.map.options().mapping, Mapping::equal_area);
    expect_identical_samples(map, loaded.map, 9, 10000);
}

// Offsets in a table file (docs/table-format.md).
constexpr size_t kPreamble = 32, kVersionAt = 8, kTotalSizeAt = 16, kMetadataSizeAt = 24;
constexpr size_t kMappingByte = kPreamble + 5 * 4 + 3 * 4 + 3;  // after size, kind, flags, alpha, luma, axes
constexpr size_t kFixedMetadata = 100;                          // the fields before the three strings

uint32_t u32_at(const std::vector<char>& bytes, size_t offset) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + offset, sizeof v);
    return v;
}

// Size of the metadata block's fields, without version 3's padding.
size_t unpadded_metadata(const std::vector<char>& bytes) {
    size_t end = kFixedMetadata;
    for (int i = 0; i < 3; ++i) end += 4 + u32_at(bytes, kPreamble + end);
    return end;
}

// Recomputes the header checksum after an edit of the header.
void reseal(std::vector<char>& bytes) {
    const uint32_t m = u32_at(bytes, kMetadataSizeAt);
    const uint64_t digest = hash64(std::as_bytes(std::span(bytes.data(), kPreamble + m)));
    std::memcpy(bytes.data() + kPreamble + m, &digest, sizeof digest);
}

// The same table as an older version writes it: version 4 has no build options; before
// it, no bins-section size (and no bins); before version 3 no metadata padding; version 1
// also has a reserved 0 where later versions keep the mapping.
std::vector<char> as_version(std::vector<char> bytes, uint32_t version) {
    const uint32_t m = u32_at(bytes, kMetadataSizeAt);
    uint32_t unpadded = static_cast<uint32_t>(unpadded_metadata(bytes));
    if (version == 4)
        unpadded += 4;  // keeps the bins-section size
    else
        EXPECT_EQ(u32_at(bytes, kPreamble + unpadded), 0u) << "a table with bins has no older version";
    bytes.erase(bytes.begin() + kPreamble + unpadded, bytes.begin() + kPreamble + m);
    if (version >= 3) {
        const uint32_t padding = (8 - unpadded % 8) % 8;
        bytes.insert(bytes.begin() + kPreamble + unpadded, padding, 0);
        unpadded += padding;
    }
    const uint64_t total = bytes.size();
    std::memcpy(bytes.data() + kVersionAt, &version, sizeof version);
    std::memcpy(bytes.data() + kTotalSizeAt, &total, sizeof total);
    std::memcpy(bytes.data() + kMetadataSizeAt, &unpadded, sizeof unpadded);
    if (version == 1) bytes[kMappingByte] = 0;
    reseal(bytes);
    return bytes;
}

// Version 1 had a reserved zero byte where version 2 keeps the mapping: such files are
// equirectangular and still read; a version 1 file with another byte there is corrupt.
TEST_F(TableTest, VersionOneTablesStillRead) {
    const fs::path path = saved_table();
    std::vector<char> bytes = bytes_of(path);
    ASSERT_EQ(bytes[kMappingByte], 1);  // equirect, as version 3 writes it
    bytes = as_version(bytes, 1);
    write_bytes(path, bytes);
    const Table loaded = read_table(path);
    EXPECT_EQ(loaded.map.options().mapping, Mapping::equirect);
    expect_identical_samples(map_, loaded.map, 4, 1000);
    bytes[kMappingByte] = 2;
    reseal(bytes);
    write_bytes(path, bytes);
    expect_rejected(path, "unknown mapping");
}

// Version 2 is version 3 without the metadata padding; its payload may be misaligned in
// the file, so it is read into memory rather than used from a mapping.
TEST_F(TableTest, VersionTwoTablesStillRead) {
    const fs::path path = saved_table();
    write_bytes(path, as_version(bytes_of(path), 2));
    const Table loaded = read_table(path);
    EXPECT_FALSE(loaded.mapped);
    expect_identical_samples(map_, loaded.map, 5, 1000);
}

// Version 3 is version 4 without the bins-section size: such tables read, in place from
// a mapping, and have no bins.
TEST_F(TableTest, VersionThreeTablesStillReadFromAMapping) {
    const fs::path path = saved_table();
    write_bytes(path, as_version(bytes_of(path), 3));
    const Table loaded = read_table(path);
    EXPECT_EQ(loaded.version, 3u);
#if defined(__unix__) || defined(__APPLE__)
    EXPECT_TRUE(loaded.mapped);
#endif
    EXPECT_FALSE(loaded.bins);
    expect_identical_samples(map_, loaded.map, 5, 1000);
}

// Version 4 is version 5 without the build options: such tables read, with none.
TEST_F(TableTest, VersionFourTablesStillReadWithoutBuildOptions) {
    const fs::path path = saved_table();
    write_bytes(path, as_version(bytes_of(path), 4));
    const Table loaded = read_table(path);
    EXPECT_EQ(loaded.version, 4u);
    EXPECT_EQ(loaded.source.name, source_.name);
    EXPECT_EQ(loaded.source.build_options, "");
    expect_identical_samples(map_, loaded.map, 5, 1000);
    EXPECT_EQ(read_table_header(path).source.build_options, "");
}

// The header alone says what a tool needs to tell whether a table is up to date, and is
// checked as read_table checks it; the payload is not read.
TEST_F(TableTest, TheHeaderAloneGivesSizeOptionsAndSource) {
    const fs::path path = saved_table();
    const TableHeader header = read_table_header(path);
    EXPECT_EQ(header.version, kTableVersion);
    EXPECT_EQ(header.width, map_.width());
    EXPECT_EQ(header.height, map_.height());
    EXPECT_EQ(header.source.content_hash, source_.content_hash);
    EXPECT_EQ(header.source.build_options, source_.build_options);
    EXPECT_EQ(header.options.compensation.alpha, 0.75f);
    EXPECT_EQ(header.stats.mean_luminance, map_.stats().mean_luminance);
    EXPECT_FALSE(header.compact);
    EXPECT_FALSE(header.binned);

    std::vector<char> bytes = bytes_of(path);
    bytes[bytes.size() - 9] ^= 1;  // the payload's last byte
    write_bytes(path, bytes);
    EXPECT_NO_THROW(read_table_header(path));
    bytes[kPreamble + 1] ^= 1;  // the width
    write_bytes(path, bytes);
    EXPECT_THROW(read_table_header(path), TableError);
    bytes.resize(bytes.size() - 1);
    write_bytes(path, bytes);
    EXPECT_THROW(read_table_header(path), TableError);
    EXPECT_THROW(read_table_header(dir_ / "missing.envmis"), TableError);
}

// read_table_header opens and checks a file as read_table does: the same message for
// every file whose header it cannot read.
TEST_F(TableTest, TheHeaderAloneFailsWithReadTablesMessages) {
    const auto message = [](auto&& read) -> std::string {
        try {
            read();
        } catch (const TableError& e) {
            return e.what();
        }
        return "accepted";
    };
    const fs::path path = saved_table();
    const std::vector<char> good = bytes_of(path);
    const auto expect_same = [&](const fs::path& p, const std::string& problem) {
        const std::string header = message([&] { read_table_header(p); });
        EXPECT_NE(header.find(problem), std::string::npos) << header;
        EXPECT_EQ(header, message([&] { read_table(p, TableLoading::copy); }));
        EXPECT_EQ(header, message([&] { read_table(p, TableLoading::map); }));
    };
    expect_same(dir_ / "missing.envmis", "no such file");
    expect_same(dir_, "not a regular file");
    write_bytes(path, {good.begin(), good.begin() + 20});
    expect_same(path, "truncated");
    write_bytes(path, {good.begin(), good.end() - 1});
    expect_same(path, "truncated");
    write_bytes(path, {'#', '?', 'R', 'A', 'D', 'I', 'A', 'N', 'C', 'E', '\n'});
    expect_same(path, "not an envmis table");
}

// Version 3 pads the metadata block with zeros to a multiple of 8 bytes, so that the
// payload's arrays are aligned; anything else there is an error.
TEST_F(TableTest, MetadataPaddingIsZerosToAMultipleOfEight) {
    const fs::path path = saved_table();
    std::vector<char> bytes = bytes_of(path);
    const uint32_t m = u32_at(bytes, kMetadataSizeAt);
    EXPECT_EQ(m % 8, 0u);
    ASSERT_GT(m, unpadded_metadata(bytes)) << "choose a source name that needs padding";
    bytes[kPreamble + m - 1] = 1;
    reseal(bytes);
    write_bytes(path, bytes);
    expect_rejected(path, "unexpected bytes");
}

// A radiance read into memory is allocated for huge pages, as a built map's is
// (large_vector.h): lookups read it at random texels.
TEST_F(TableTest, ACopiedLoadOfALargeMapHoldsItsRadianceFromAHugePageBoundary) {
    const fs::path path = dir_ / "large.envmis";
    write_table(path, build_env_map(test::constant_map(1024, 512, {1, 1, 1})), source_);  // 6 MiB of pixels
    const Table copied = read_table(path, TableLoading::copy);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(copied.map.radiance().pixels.data()) % (size_t{2} << 20), 0u);
}

// By default a full table's radiance is used in place from a mapping of the file (where
// the platform has mmap); loading with TableLoading::copy reads it into memory. Both
// give the saved map, bit for bit.
TEST_F(TableTest, MappedAndCopiedLoadsAreBitIdentical) {
    const fs::path path = saved_table();
    const Table mapped = read_table(path), copied = read_table(path, TableLoading::copy);
#if defined(__unix__) || defined(__APPLE__)
    EXPECT_TRUE(mapped.mapped);
#endif
    EXPECT_FALSE(copied.mapped);
    expect_identical_samples(map_, mapped.map, 6, 100000);
    expect_identical_samples(map_, copied.map, 6, 1000);
    ASSERT_EQ(mapped.map.radiance().pixels.size(), map_.radiance().pixels.size());
    EXPECT_EQ(std::memcmp(mapped.map.radiance().pixels.data(), map_.radiance().pixels.data(),
                          map_.radiance().pixels.size_bytes()),
              0);
    // Compact tables decode their radiance: nothing to map.
    write_table(path, map_, source_, TableEncoding::compact);
    EXPECT_FALSE(read_table(path).mapped);
}

// write_table replaces a file by renaming a new one over it: a map loaded from the old
// file, and copies of that map, keep sampling it after the loaded Table is gone.
TEST_F(TableTest, AMappedMapOutlivesItsTableAndTheFilesReplacement) {
    const fs::path path = saved_table();
    EnvMap kept;
    {
        const Table t = read_table(path);
        kept = t.map;
    }
    write_table(path, build_env_map(test::constant_map(8, 4, {1, 2, 3})), source_);
    expect_identical_samples(map_, kept, 7, 10000);
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

// Offsets of the statistics in the metadata block (docs/table-format.md), from the file's start.
constexpr size_t kReservedAt = 28, kMeanAt = kPreamble + 36, kThresholdAt = kPreamble + 44, kMaxAt = kPreamble + 48,
                 kMinAt = kPreamble + 52, kZeroedAt = kPreamble + 56, kFallbackAt = kPreamble + 64,
                 kNanCountAt = kPreamble + 68;

// A crafted table passes its checksums: every statistic is checked for what a writer
// could have made of the map, and a bad one is named.
TEST_F(TableTest, ImpossibleStatisticsAreRejectedNamingTheField) {
    const fs::path path = saved_table();
    const std::vector<char> good = bytes_of(path);
    ASSERT_NO_THROW(read_table(path));
    const auto edited = [&](size_t offset, auto value, const std::string& problem) {
        std::vector<char> bytes = good;
        std::memcpy(bytes.data() + offset, &value, sizeof value);
        reseal(bytes);
        write_bytes(path, bytes);
        SCOPED_TRACE(problem);
        expect_rejected(path, problem);
    };
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    edited(kMeanAt, nan, "invalid mean luminance");
    edited(kMeanAt, inf, "invalid mean luminance");
    edited(kMeanAt, -1.0, "invalid mean luminance");
    edited(kMeanAt, 3e38, "invalid mean luminance");  // above the max luminance, and 4 pi of it overflows
    edited(kThresholdAt, std::numeric_limits<float>::quiet_NaN(), "invalid threshold");
    edited(kMaxAt, std::numeric_limits<float>::infinity(), "invalid max luminance");
    edited(kMinAt, -1.0f, "invalid min luminance");
    edited(kZeroedAt, uint64_t{96 * 48 + 1}, "invalid zeroed texel count");
    edited(kNanCountAt, ~uint64_t{0}, "invalid NaN count");
    edited(kFallbackAt, uint32_t{2}, "invalid fallback uniform");  // on a map that is not black
    edited(kReservedAt, uint32_t{1}, "reserved field is 1");
}

// Recomputes the payload checksum (a table without bins: it ends the file) after an edit
// of the payload.
void reseal_payload(std::vector<char>& bytes) {
    const size_t payload = kPreamble + u32_at(bytes, kMetadataSizeAt) + 8, end = bytes.size() - 8;
    const uint64_t digest = hash64(std::as_bytes(std::span(bytes.data() + payload, end - payload)));
    std::memcpy(bytes.data() + end, &digest, sizeof digest);
}

constexpr size_t kLumaAt = kPreamble + 20;

// A crafted table whose checksums were recomputed states facts that its payload must
// confirm: luminance weights in range, the statistics the radiance's,
// each density value the radiance's.
TEST_F(TableTest, HeaderFactsThatThePayloadContradictsAreRejectedNamingThem) {
    const fs::path path = saved_table();
    const std::vector<char> good = bytes_of(path);
    const size_t payload = kPreamble + u32_at(good, kMetadataSizeAt) + 8, texels = 96 * 48;
    const auto rejected = [&](std::vector<char> bytes, const std::string& problem) {
        reseal(bytes);
        reseal_payload(bytes);
        write_bytes(path, bytes);
        SCOPED_TRACE(problem);
        expect_rejected(path, problem);
    };
    const auto with = [&](size_t offset, auto value) {
        std::vector<char> bytes = good;
        std::memcpy(bytes.data() + offset, &value, sizeof value);
        return bytes;
    };
    const EnvMapStats& stats = map_.stats();
    ASSERT_GT(stats.threshold, 0) << "a compensated map";
    rejected(with(kThresholdAt, 1e30f), "threshold");
    rejected(with(kThresholdAt, stats.threshold * 1.01f), "threshold");
    rejected(with(kThresholdAt, stats.threshold * 1.01f), "is not the radiance's");
    rejected(with(kLumaAt, 1e30f), "invalid luma coefficient red 1e+30");
    rejected(with(kMeanAt, stats.mean_luminance * 1.01), "mean luminance");
    rejected(with(kMaxAt, stats.max_luminance * 1.01f), "max luminance");
    rejected(with(kMinAt, stats.min_positive_luminance * 1.01f), "min luminance");
    // A texel compensation zeroes holds exactly 0: no slack to move mass into.
    const std::vector<float> density = map_.density();
    const size_t zeroed = static_cast<size_t>(std::find(density.begin(), density.end(), 0.0f) - density.begin());
    ASSERT_LT(zeroed, texels);
    rejected(with(payload + 4 * zeroed, 1e-30f), "density values are not those of the radiance");
    std::vector<char> zeros = good;
    std::fill_n(zeros.begin() + static_cast<std::ptrdiff_t>(payload), 4 * texels, char{0});
    rejected(zeros, "density values are not those of the radiance");
    std::vector<char> bright = good;
    const float top = std::numeric_limits<float>::max();
    for (size_t c = 0; c < 3; ++c) std::memcpy(bright.data() + payload + 4 * texels + 12 * 100 + 4 * c, &top, 4);
    rejected(bright, "is not the radiance's");
    // The untouched table, resealed, still reads.
    write_bytes(path, good);
    EXPECT_NO_THROW(read_table(path));
}

// The statistics of a black map and of a constant one (fallbacks) are what the reader expects.
TEST_F(TableTest, FallbackTablesPassTheStatisticsChecks) {
    for (const Rgb c : {Rgb{0, 0, 0}, Rgb{0.5f, 0.5f, 0.5f}}) {
        const EnvMap map = build_env_map(test::constant_map(16, 8, c));
        write_table(dir_ / "fallback.envmis", map, source_);
        EXPECT_EQ(read_table(dir_ / "fallback.envmis").map.stats().fallback, map.stats().fallback);
    }
}

TEST_F(TableTest, WritingIsAtomic) {
    const fs::path path = saved_table();
    const auto before = bytes_of(path);
    // A destination in a missing folder fails, leaving nothing behind.
    EXPECT_THROW(write_table(dir_ / "missing" / "x.envmis", map_, source_), TableError);
    EXPECT_FALSE(fs::exists(dir_ / "missing"));
    // Overwriting replaces the file whole and leaves no temporary file.
    write_table(path, build_env_map(test::constant_map(8, 4, {1, 2, 3})), source_);
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

// ---------------------------------------------------------------------------------
// Binned tables (version 4 and later): the plain map, then the bins' layout with its checksum.

EnvMap plain_sky() {
    EnvMapOptions o;
    o.compensation.enabled = false;
    o.axes = Axes::parse("y-up");
    return build_env_map(test::sun_sky_map(96, 48), o);
}

BinnedEnvMap small_binned(EnvMap plain) {
    BinnedOptions o;
    o.bins_per_side = 4;
    return build_bins(std::move(plain), o);
}

// `loaded` samples exactly as `expected`, for every lobe class and normals across all bins.
void expect_identical_binned_samples(const BinnedEnvMap& expected, const BinnedEnvMap& loaded, uint64_t seed, int n) {
    ASSERT_EQ(loaded.classes(), expected.classes());
    const BinnedEnvMapView a = expected.view(), b = loaded.view();
    test::Rng rng(seed);
    for (int i = 0; i < n; ++i) {
        const Vec3 normal = octahedral_normal(rng.uniform(), rng.uniform());
        const uint32_t lobe = static_cast<uint32_t>(i) % expected.classes();
        const Vec2 u = rng.uniform2();
        const float c = rng.uniform();
        const LobeAxis at{normal, rng.uniform()};  // views of every obliquity
        const EnvSample x = a.sample(at, lobe, c, u), y = b.sample(at, lobe, c, u);
        ASSERT_EQ(std::memcmp(&x, &y, sizeof x), 0) << "sample " << i;
        ASSERT_EQ(a.pdf(at, lobe, c, x.direction), b.pdf(at, lobe, c, x.direction));
    }
}

void expect_same_layout(const BinLayout& a, const BinLayout& b) {
    EXPECT_EQ(a.bins_per_side, b.bins_per_side);
    EXPECT_EQ(a.diffuse_bins_per_side, b.diffuse_bins_per_side);
    EXPECT_EQ(a.cell_columns, b.cell_columns);
    EXPECT_EQ(a.cell_rows, b.cell_rows);
    EXPECT_EQ(a.lobe_exponents, b.lobe_exponents);
    ASSERT_EQ(a.choices.size(), b.choices.size());
    for (size_t i = 0; i < a.choices.size(); ++i) {
        EXPECT_EQ(a.choices[i].alpha, b.choices[i].alpha) << i;
        EXPECT_EQ(a.choices[i].threshold, b.choices[i].threshold) << i;
        EXPECT_EQ(a.choices[i].min_view_cos, b.choices[i].min_view_cos) << i;
    }
}

class BinnedTableTest : public TableTest {
protected:
    fs::path saved_binned_table() {
        binned_ = small_binned(plain_sky());
        const fs::path path = dir_ / "binned.envmis";
        write_table(path, binned_, source_);
        return path;
    }
    BinnedEnvMap binned_;
};

// Offset of the bins-section size in the metadata block (after the three strings).
size_t bins_size_at(const std::vector<char>& bytes) { return kPreamble + unpadded_metadata(bytes); }

// The bins section (without its checksum): where it starts and its size.
std::pair<size_t, size_t> bins_section_of(const std::vector<char>& bytes) {
    const size_t size = u32_at(bytes, bins_size_at(bytes));
    return {bytes.size() - 8 - size, size};
}

// Recomputes the bins section's checksum after an edit of it.
void reseal_bins(std::vector<char>& bytes) {
    const auto [at, size] = bins_section_of(bytes);
    const uint64_t digest = hash64(std::as_bytes(std::span(bytes.data() + at, size)));
    std::memcpy(bytes.data() + at + size, &digest, sizeof digest);
}

TEST_F(BinnedTableTest, BinnedTablesRoundTripBitIdenticallyMappedOrCopied) {
    const fs::path path = saved_binned_table();
    for (TableLoading loading : {TableLoading::map, TableLoading::copy}) {
        Table table = read_table(path, loading);
        EXPECT_EQ(table.version, kTableVersion);
        ASSERT_TRUE(table.bins);
        expect_same_layout(*table.bins, binned_.layout());
        const BinnedEnvMap loaded = binned_map(std::move(table));
        expect_identical_binned_samples(binned_, loaded, 21, 20000);
        expect_identical_samples(binned_.plain_map(), loaded.plain_map(), 22, 1000);
    }
#if defined(__unix__) || defined(__APPLE__)
    EXPECT_TRUE(read_table(path).mapped);
#endif
    EXPECT_TRUE(read_table_header(path).binned);
    const std::vector<char> bytes = bytes_of(path);
    const Table parsed = parse_table(std::as_bytes(std::span(bytes)), "mem");
    ASSERT_TRUE(parsed.bins);
    expect_same_layout(*parsed.bins, binned_.layout());
}

// A compact binned table holds the RGBE-rounded plain map; the bins are rebuilt over it
// from the stored layout.
TEST_F(BinnedTableTest, CompactBinnedTablesRebuildTheBinsOverTheRoundedMap) {
    const BinnedEnvMap binned = small_binned(plain_sky());
    const fs::path path = dir_ / "compact.envmis";
    write_table(path, binned, source_, TableEncoding::compact);
    const BinnedEnvMap expected(
        build_env_map(rgbe_round(binned.radiance_map().radiance()), binned.radiance_map().options()), binned.layout());
    expect_identical_binned_samples(expected, binned_map(read_table(path)), 23, 10000);
}

TEST_F(BinnedTableTest, AnEmptyBinnedMapIsNotWritten) {
    EXPECT_THROW(write_table(dir_ / "empty.envmis", BinnedEnvMap(), source_), TableError);
    EXPECT_FALSE(fs::exists(dir_ / "empty.envmis"));
}

TEST_F(BinnedTableTest, TablesWithoutBinsHaveNoneAndCannotGiveABinnedMap) {
    const fs::path path = saved_table();
    Table table = read_table(path);
    EXPECT_EQ(table.version, kTableVersion);
    EXPECT_FALSE(table.bins);
    try {
        binned_map(std::move(table));
        ADD_FAILURE() << "a table without bins gave a binned map";
    } catch (const TableError& e) {
        EXPECT_NE(std::string(e.what()).find(path.string() + ": has no bins"), std::string::npos) << e.what();
    }
}

TEST_F(BinnedTableTest, DamagedBinsSectionsAreRejectedNamingTheProblem) {
    const fs::path path = saved_binned_table();
    const std::vector<char> good = bytes_of(path);
    const auto [at, size] = bins_section_of(good);
    ASSERT_EQ(size, 20 + 4 * 3 + 12 * (7 * 7 + 2 * 16u));  // g 4, the diffuse class's 7
    std::vector<char> bytes = good;
    bytes[at + size / 2] ^= 0x10;
    write_bytes(path, bytes);
    expect_rejected(path, "corrupted bins section");
    for (size_t cut : {size_t{1}, size_t{8}, size / 2}) {
        write_bytes(path, {good.begin(), good.end() - static_cast<std::ptrdiff_t>(cut)});
        expect_rejected(path, "truncated");
    }
    const auto field = [&](size_t offset, uint32_t value, const std::string& problem) {
        bytes = good;
        std::memcpy(bytes.data() + at + offset, &value, sizeof value);
        reseal_bins(bytes);
        write_bytes(path, bytes);
        expect_rejected(path, problem);
    };
    field(0, 65, "65 bins per side, not 1 to 64");
    field(0, 5, "does not hold 3 lobe classes of 49 diffuse and 25 glossy bins");
    field(4, 97, "cell grid 97x");
    field(8, 0, "does not fit a 96x48 map");
    field(12, 9, "9 lobe classes, not 1 to 8");
    field(16, 0, "0 diffuse bins per side, not 1 to 64");
    field(16, 3, "does not hold 3 lobe classes of 9 diffuse and 16 glossy bins");
    field(20, std::bit_cast<uint32_t>(1.0f), "lobe exponents");
    field(20 + 12 + 4, std::bit_cast<uint32_t>(NAN), "not finite");
    field(20 + 12 + 4, std::bit_cast<uint32_t>(-1.0f), "threshold is negative");
    field(20 + 12 + 8, std::bit_cast<uint32_t>(0.5f), "view limit is not in [0, 1], or not 0 for a diffuse");
    const size_t glossy = 20 + 12 + 12 * 49;  // the first glossy bin's choice
    field(glossy + 8, std::bit_cast<uint32_t>(1.5f), "view limit is not in [0, 1]");
    field(glossy + 8, std::bit_cast<uint32_t>(NAN), "view limit is not in [0, 1]");
}

// Version 6 is version 7 without the bins' view limits: its binned tables read, every
// bin sampling its own density at every view.
TEST_F(BinnedTableTest, VersionSixBinnedTablesReadWithoutViewLimits) {
    const fs::path path = saved_binned_table();
    std::vector<char> bytes = bytes_of(path);
    const auto [at, size] = bins_section_of(bytes);
    const size_t choices = binned_.layout().choice_count(), first = size - 12 * choices;
    std::vector<char> section(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                              bytes.begin() + static_cast<std::ptrdiff_t>(at + first));
    for (size_t i = 0; i < choices; ++i) {
        const auto choice = bytes.begin() + static_cast<std::ptrdiff_t>(at + first + 12 * i);
        section.insert(section.end(), choice, choice + 8);
    }
    bytes.resize(at);
    bytes.insert(bytes.end(), section.begin(), section.end());
    bytes.resize(bytes.size() + 8);
    const auto old_size = static_cast<uint32_t>(section.size());
    const uint32_t version = 6;
    const uint64_t total = bytes.size();
    std::memcpy(bytes.data() + bins_size_at(bytes), &old_size, sizeof old_size);
    std::memcpy(bytes.data() + kVersionAt, &version, sizeof version);
    std::memcpy(bytes.data() + kTotalSizeAt, &total, sizeof total);
    reseal(bytes);
    reseal_bins(bytes);
    write_bytes(path, bytes);
    Table table = read_table(path);
    EXPECT_EQ(table.version, 6u);
    ASSERT_TRUE(table.bins);
    BinLayout expected = binned_.layout();
    for (BinChoice& c : expected.choices) c.min_view_cos = 0;
    expect_same_layout(*table.bins, expected);
}

TEST_F(BinnedTableTest, ImplausibleBinsSectionSizesAreRejectedBeforeReading) {
    const fs::path path = saved_binned_table();
    std::vector<char> bytes = bytes_of(path);
    const uint32_t huge = 1u << 30;
    std::memcpy(bytes.data() + bins_size_at(bytes), &huge, sizeof huge);
    reseal(bytes);
    write_bytes(path, bytes);
    expect_rejected(path, "invalid bins section size 1073741824");
}

// A layout the parser accepts but the map's rebuild refuses (a threshold between the
// histogram's edges): binned_map names the file.
TEST_F(BinnedTableTest, BinsThatDoNotFitTheMapAreATableError) {
    const fs::path path = saved_binned_table();
    std::vector<char> bytes = bytes_of(path);
    const auto [at, size] = bins_section_of(bytes);
    const float odd = 0.123456789f;
    std::memcpy(bytes.data() + at + 20 + 12 + 4, &odd, sizeof odd);
    reseal_bins(bytes);
    write_bytes(path, bytes);
    try {
        binned_map(read_table(path));
        ADD_FAILURE() << "an off-edge threshold was accepted";
    } catch (const TableError& e) {
        EXPECT_NE(std::string(e.what()).find(path.string() + ": bins do not fit the map"), std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace envmis
