// Specification of image reading and writing (image_io.h). Input files are made here,
// with OpenImageIO or by hand, in a temporary folder per test.
#include "envmis/io/image_io.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "envmis/io/colour.h"
#include "envmis/math/hash.h"
#include "errors.h"

namespace envmis::io {
namespace {

namespace fs = std::filesystem;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Distinct values, exact in float: channel c of pixel (x, y) of a w-wide image.
std::vector<float> pattern(uint32_t w, uint32_t h, int channels) {
    std::vector<float> values;
    for (uint32_t i = 0; i < w * h; ++i)
        for (int c = 0; c < channels; ++c)
            values.push_back(0.5f * static_cast<float>(i) + 0.125f * static_cast<float>(c + 1));
    return values;
}

// The RGB the loader should make of `values`: grey (+alpha) files become R = G = B.
Rgb expected_rgb(const std::vector<float>& values, size_t pixel, int channels) {
    const float* v = &values[pixel * channels];
    return channels >= 3 ? Rgb{v[0], v[1], v[2]} : Rgb{v[0], v[0], v[0]};
}

void expect_same(const Rgb& a, const Rgb& b, size_t pixel) {
    EXPECT_EQ(a.r, b.r) << "pixel " << pixel;
    EXPECT_EQ(a.g, b.g) << "pixel " << pixel;
    EXPECT_EQ(a.b, b.b) << "pixel " << pixel;
}

void expect_pattern(const LoadedImage& loaded, uint32_t w, uint32_t h, int channels) {
    ASSERT_EQ(loaded.image.width, w);
    ASSERT_EQ(loaded.image.height, h);
    ASSERT_EQ(loaded.image.pixels.size(), size_t{w} * h);
    EXPECT_EQ(loaded.channels, static_cast<uint32_t>(channels));
    const auto values = pattern(w, h, channels);
    for (size_t i = 0; i < loaded.image.pixels.size(); ++i)
        expect_same(loaded.image.pixels[i], expected_rgb(values, i, channels), i);
}

void write_oiio(const fs::path& path, const char* format, const OIIO::ImageSpec& spec, const void* pixels,
                OIIO::TypeDesc pixel_type = OIIO::TypeDesc::FLOAT) {
    auto out = OIIO::ImageOutput::create(format);
    if (!out || !out->open(path.string(), spec) || !out->write_image(pixel_type, pixels) || !out->close())
        throw std::runtime_error("test setup: cannot write " + path.string() + ": " +
                                 (out ? out->geterror() : OIIO::geterror()));
}

void write_pattern(const fs::path& path, const char* format, uint32_t w, uint32_t h, int channels,
                   OIIO::TypeDesc file_type = OIIO::TypeDesc::FLOAT, int tile = 0) {
    OIIO::ImageSpec spec(static_cast<int>(w), static_cast<int>(h), channels, file_type);
    spec.tile_width = spec.tile_height = tile;
    write_oiio(path, format, spec, pattern(w, h, channels).data());
}

// PFM stores little-endian float rows from the bottom up; the loader must flip them.
void write_pfm(const fs::path& path, uint32_t w, uint32_t h, const std::vector<float>& rgb_top_down) {
    std::ofstream out(path, std::ios::binary);
    out << "PF\n" << w << " " << h << "\n-1.0\n";
    for (uint32_t row = h; row-- > 0;)
        out.write(reinterpret_cast<const char*>(&rgb_top_down[size_t{row} * w * 3]),
                  static_cast<std::streamsize>(w * 3 * sizeof(float)));
}

std::vector<std::byte> file_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> chars{std::istreambuf_iterator<char>(in), {}};
    std::vector<std::byte> bytes(chars.size());
    std::memcpy(bytes.data(), chars.data(), chars.size());
    return bytes;
}

std::vector<std::string> folder_entries(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
    return names;
}

template <class Action>
void expect_image_error(Action&& action, std::initializer_list<std::string> parts) {
    test::expect_error<ImageError>(std::forward<Action>(action), parts);
}

// These expectations are about the shipped OCIO config, whatever $OCIO the runner has.
class ShippedColourConfig : public ::testing::Environment {
    void SetUp() override { unsetenv("OCIO"); }
};
::testing::Environment* const kShippedColourConfig = ::testing::AddGlobalTestEnvironment(new ShippedColourConfig);

class ImageIo : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("envmis_image_io_" + std::to_string(getpid()) + "_" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    fs::path file(const std::string& name) const { return dir_ / name; }

    fs::path dir_;
};

// --- formats and layouts

TEST_F(ImageIo, ReadsAScanlineExrExactly) {
    write_pattern(file("a.exr"), "openexr", 7, 3, 3);
    const LoadedImage loaded = load_image(file("a.exr"));
    expect_pattern(loaded, 7, 3, 3);
    EXPECT_EQ(loaded.format, "openexr");
    EXPECT_EQ(loaded.input_colorspace, "lin_rec709");
    EXPECT_EQ(loaded.working_colorspace, "lin_rec709");
}

TEST_F(ImageIo, ReadsATiledExrWithPartialTiles) {
    write_pattern(file("tiled.exr"), "openexr", 37, 19, 3, OIIO::TypeDesc::FLOAT, 16);
    ASSERT_EQ(OIIO::ImageInput::open(file("tiled.exr").string())->spec().tile_width, 16);
    expect_pattern(load_image(file("tiled.exr")), 37, 19, 3);
}

TEST_F(ImageIo, ReadsTheFirstPartOfAMultiPartExr) {
    const OIIO::ImageSpec specs[2] = {{4, 2, 3, OIIO::TypeDesc::FLOAT}, {4, 2, 3, OIIO::TypeDesc::FLOAT}};
    const std::vector<float> first(4 * 2 * 3, 1.0f), second(4 * 2 * 3, 2.0f);
    const std::string name = file("parts.exr").string();
    auto out = OIIO::ImageOutput::create("openexr");
    ASSERT_TRUE(out->open(name, 2, specs) && out->write_image(OIIO::TypeDesc::FLOAT, first.data()) &&
                out->open(name, specs[1], OIIO::ImageOutput::AppendSubimage) &&
                out->write_image(OIIO::TypeDesc::FLOAT, second.data()) && out->close())
        << out->geterror();
    for (const Rgb& p : load_image(file("parts.exr")).image.pixels) expect_same(p, {1, 1, 1}, 0);
}

// An EXR whose data window (the pixels stored: the pattern, data_w x data_h at
// (data_x, data_y)) differs from its display window (display_w x display_h at the origin).
void write_windowed_exr(const fs::path& path, int data_x, int data_y, uint32_t data_w, uint32_t data_h,
                        uint32_t display_w, uint32_t display_h) {
    OIIO::ImageSpec spec(static_cast<int>(data_w), static_cast<int>(data_h), 3, OIIO::TypeDesc::FLOAT);
    spec.x = data_x;
    spec.y = data_y;
    spec.full_x = spec.full_y = 0;
    spec.full_width = static_cast<int>(display_w);
    spec.full_height = static_cast<int>(display_h);
    write_oiio(path, "openexr", spec, pattern(data_w, data_h, 3).data());
}

// The EXR rule: the image is the display window; where the data window does not
// cover it, black.
TEST_F(ImageIo, ACroppedExrIsItsDisplayWindowBlackOutsideTheDataWithANotice) {
    write_windowed_exr(file("crop.exr"), 2, 1, 3, 2, 8, 4);
    const LoadedImage loaded = load_image(file("crop.exr"));
    ASSERT_EQ(loaded.image.width, 8u);
    ASSERT_EQ(loaded.image.height, 4u);
    const auto values = pattern(3, 2, 3);
    for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 8; ++x) {
            const bool inside = x >= 2 && x < 5 && y >= 1 && y < 3;
            const Rgb expected = inside ? expected_rgb(values, (y - 1) * 3 + (x - 2), 3) : Rgb{};
            expect_same(loaded.image.pixels[y * 8 + x], expected, y * 8 + x);
        }
    ASSERT_EQ(loaded.notices.size(), 1u);
    EXPECT_NE(loaded.notices[0].find(file("crop.exr").string()), std::string::npos) << loaded.notices[0];
    EXPECT_NE(loaded.notices[0].find("black where it has no data"), std::string::npos) << loaded.notices[0];
}

// Overscan: data beyond the display window is cropped away.
TEST_F(ImageIo, AnOverscanExrIsCroppedToItsDisplayWindowWithANotice) {
    write_windowed_exr(file("overscan.exr"), -1, -2, 8, 6, 4, 2);
    const LoadedImage loaded = load_image(file("overscan.exr"));
    ASSERT_EQ(loaded.image.width, 4u);
    ASSERT_EQ(loaded.image.height, 2u);
    const auto values = pattern(8, 6, 3);
    for (uint32_t y = 0; y < 2; ++y)
        for (uint32_t x = 0; x < 4; ++x)
            expect_same(loaded.image.pixels[y * 4 + x], expected_rgb(values, (y + 2) * 8 + (x + 1), 3), y * 4 + x);
    ASSERT_EQ(loaded.notices.size(), 1u);
    EXPECT_NE(loaded.notices[0].find("data outside it cropped"), std::string::npos) << loaded.notices[0];
    EXPECT_EQ(loaded.notices[0].find("black"), std::string::npos) << loaded.notices[0];
}

TEST_F(ImageIo, MatchingWindowsGiveNoNotice) {
    write_pattern(file("a.exr"), "openexr", 7, 3, 3);
    EXPECT_TRUE(load_image(file("a.exr")).notices.empty());
}

TEST_F(ImageIo, ReadsRadianceHdrWithinItsEightBitMantissa) {
    write_pattern(file("a.hdr"), "hdr", 5, 4, 3);
    const LoadedImage loaded = load_image(file("a.hdr"));
    EXPECT_EQ(loaded.format, "hdr");
    EXPECT_EQ(loaded.input_colorspace, "lin_rec709");
    const auto values = pattern(5, 4, 3);
    for (size_t i = 0; i < loaded.image.pixels.size(); ++i) {
        const Rgb e = expected_rgb(values, i, 3), p = loaded.image.pixels[i];
        const float tolerance = std::max({e.r, e.g, e.b}) / 128;  // RGBE shares one exponent per pixel
        EXPECT_NEAR(p.r, e.r, tolerance) << i;
        EXPECT_NEAR(p.g, e.g, tolerance) << i;
        EXPECT_NEAR(p.b, e.b, tolerance) << i;
    }
}

TEST_F(ImageIo, ReadsPfmTopRowFirstAndAsLinear) {
    write_pfm(file("a.pfm"), 7, 3, pattern(7, 3, 3));
    const LoadedImage loaded = load_image(file("a.pfm"));
    expect_pattern(loaded, 7, 3, 3);
    EXPECT_EQ(loaded.format, "pnm");
    EXPECT_EQ(loaded.input_colorspace, "lin_rec709");
}

TEST_F(ImageIo, ReadsAFloatTiffAsLinear) {
    write_pattern(file("a.tif"), "tiff", 7, 3, 3);
    const LoadedImage loaded = load_image(file("a.tif"));
    expect_pattern(loaded, 7, 3, 3);
    EXPECT_EQ(loaded.format, "tiff");
    EXPECT_EQ(loaded.input_colorspace, "lin_rec709");
}

TEST_F(ImageIo, SpreadsAGreyChannelOverRgb) {
    write_pattern(file("grey.exr"), "openexr", 7, 3, 1);
    expect_pattern(load_image(file("grey.exr")), 7, 3, 1);
}

TEST_F(ImageIo, ReadsGreyPlusAlphaAsGrey) {
    write_pattern(file("grey_alpha.exr"), "openexr", 7, 3, 2);
    expect_pattern(load_image(file("grey_alpha.exr")), 7, 3, 2);
}

TEST_F(ImageIo, IgnoresAlphaOfRgbaFiles) {
    write_pattern(file("rgba.exr"), "openexr", 7, 3, 4);
    expect_pattern(load_image(file("rgba.exr")), 7, 3, 4);
}

TEST_F(ImageIo, ReadsAOneByOneImage) {
    write_pattern(file("one.exr"), "openexr", 1, 1, 3);
    expect_pattern(load_image(file("one.exr")), 1, 1, 3);
}

// --- values

TEST_F(ImageIo, WriteExrThenLoadIsBitExact) {
    RgbImage image{9, 5, {}};
    for (uint32_t i = 0; i < 45; ++i) {
        const float v = std::ldexp(1.0f + 0.0123f * static_cast<float>(i), static_cast<int>(i) - 22);
        image.pixels.push_back({v, 1.0f / v, 0.1f * static_cast<float>(i)});
    }
    write_exr(file("round.exr"), image);
    const LoadedImage loaded = load_image(file("round.exr"));
    ASSERT_EQ(loaded.image.width, 9u);
    ASSERT_EQ(loaded.image.height, 5u);
    ASSERT_EQ(loaded.image.pixels.size(), image.pixels.size());
    EXPECT_EQ(std::memcmp(loaded.image.pixels.data(), image.pixels.data(), image.pixels.size() * sizeof(Rgb)), 0);
}

TEST_F(ImageIo, WritesZipCompressedFloatExr) {
    write_exr(file("out.exr"), RgbImage{2, 2, RgbPixels(4, Rgb{1, 2, 3})});
    const auto in = OIIO::ImageInput::open(file("out.exr").string());
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(in->spec().nchannels, 3);
    EXPECT_EQ(in->spec().get_string_attribute("compression"), "zip");
}

TEST_F(ImageIo, KeepsNaNInfinityAndNegativeValuesAsRead) {
    write_exr(file("bad.exr"), RgbImage{2, 2, {{kNaN, 1, 2}, {kInf, -kInf, 0}, {-1, -0.004f, 3}, {1, 1, 1}}});
    const auto& p = load_image(file("bad.exr")).image.pixels;
    EXPECT_TRUE(std::isnan(p[0].r));
    EXPECT_EQ(p[1].r, kInf);
    EXPECT_EQ(p[1].g, -kInf);
    EXPECT_EQ(p[2].r, -1.0f);
    EXPECT_EQ(p[2].g, -0.004f);
    LoadOptions acescg;
    acescg.working_space = "ACEScg";
    EXPECT_NO_THROW(load_image(file("bad.exr"), acescg));
}

TEST_F(ImageIo, ContentHashIsTheHashOfTheFileBytes) {
    write_pattern(file("a.exr"), "openexr", 7, 3, 3);
    write_pattern(file("b.exr"), "openexr", 7, 4, 3);
    const uint64_t a = load_image(file("a.exr")).content_hash;
    EXPECT_EQ(a, hash64(file_bytes(file("a.exr"))));
    EXPECT_NE(a, load_image(file("b.exr")).content_hash);
}

TEST_F(ImageIo, HashFileIsHash64OfAnyFilesBytesOverSeveralBlocksAndTheLoadsContentHash) {
    // 1.5 MiB: more than one of the 1 MiB blocks it reads.
    std::string bytes(size_t{3} << 19, '\0');
    for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 2654435761u >> 13);
    std::ofstream(file("table.envmis"), std::ios::binary) << bytes;
    EXPECT_EQ(hash_file(file("table.envmis")), hash64(file_bytes(file("table.envmis"))));
    write_pattern(file("a.exr"), "openexr", 7, 3, 3);
    EXPECT_EQ(hash_file(file("a.exr")), load_image(file("a.exr")).content_hash);
}

TEST_F(ImageIo, HashFileNamesAMissingFileOrAFolderAndStopsWhenAsked) {
    expect_image_error([&] { hash_file(file("nothing.envmis")); }, {"nothing.envmis", "no such file"});
    fs::create_directories(file("folder.envmis"));
    expect_image_error([&] { hash_file(file("folder.envmis")); }, {"folder.envmis", "not a regular file"});
    std::ofstream(file("x.envmis")) << "bytes\n";
    const std::atomic<bool> stop{true};
    EXPECT_THROW(hash_file(file("x.envmis"), &stop), Interrupted);
}

// --- colour spaces

TEST_F(ImageIo, ColorspaceOptionOverridesTheFileMetadata) {
    write_exr(file("half.exr"), RgbImage{1, 1, {{0.5f, 0.5f, 0.5f}}});
    LoadOptions options;
    options.colorspace = "srgb";
    const LoadedImage loaded = load_image(file("half.exr"), options);
    EXPECT_EQ(loaded.input_colorspace, "sRGB");
    EXPECT_NEAR(loaded.image.pixels[0].r, 0.21404f, 1e-4f);
}

TEST_F(ImageIo, AnUnknownColorspaceOptionIsAnErrorNamingItAndTheFile) {
    write_pattern(file("a.exr"), "openexr", 2, 2, 3);
    LoadOptions options;
    options.colorspace = "no_such_space";
    expect_image_error([&] { load_image(file("a.exr"), options); }, {"a.exr", "'no_such_space'"});
}

TEST_F(ImageIo, AnUnknownWorkingSpaceIsAnErrorNamingIt) {
    write_pattern(file("a.exr"), "openexr", 2, 2, 3);
    LoadOptions options;
    options.working_space = "no_such_space";
    expect_image_error([&] { load_image(file("a.exr"), options); }, {"a.exr", "'no_such_space'"});
}

TEST_F(ImageIo, ConvertsToTheWorkingSpaceAndReportsItsLuma) {
    write_pattern(file("a.exr"), "openexr", 3, 2, 3);
    LoadOptions options;
    options.working_space = "lin_ap1";
    const LoadedImage loaded = load_image(file("a.exr"), options);
    const ColourConfig colour(fs::path(ENVMIS_DATA_DIR) / "ocio" / "config.ocio");
    RgbPixels expected = load_image(file("a.exr")).image.pixels;
    colour.convert(expected, "lin_rec709", "ACEScg");
    EXPECT_EQ(loaded.working_colorspace, "ACEScg");
    for (size_t i = 0; i < expected.size(); ++i) expect_same(loaded.image.pixels[i], expected[i], i);
    const LumaCoefficients k = colour.luma("ACEScg");
    EXPECT_EQ(loaded.luma.r, k.r);
    EXPECT_EQ(loaded.luma.g, k.g);
    EXPECT_EQ(loaded.luma.b, k.b);
}

TEST_F(ImageIo, ReportsRec709LumaForTheDefaultWorkingSpace) {
    write_pattern(file("a.exr"), "openexr", 2, 2, 3);
    const LumaCoefficients k = load_image(file("a.exr")).luma;
    EXPECT_NEAR(k.r, 0.2126f, 1e-4f);
    EXPECT_NEAR(k.g, 0.7152f, 1e-4f);
    EXPECT_NEAR(k.b, 0.0722f, 1e-4f);
}

TEST_F(ImageIo, UntaggedIntegerImagesAreDecodedAsSrgb) {
    OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeDesc::UINT16);
    const uint16_t half_grey[3] = {32768, 32768, 32768};
    write_oiio(file("a16.tif"), "tiff", spec, half_grey, OIIO::TypeDesc::UINT16);
    const LoadedImage loaded = load_image(file("a16.tif"));
    EXPECT_EQ(loaded.input_colorspace, "sRGB");
    EXPECT_NEAR(loaded.image.pixels[0].r, 0.21404f, 1e-4f);
}

// --- PNG output

TEST_F(ImageIo, WritePngProducesAnEightBitRgbPng) {
    const Image8 image{3, 2, {0, 1, 2, 10, 20, 30, 100, 110, 120, 200, 210, 220, 253, 254, 255, 128, 64, 32}};
    write_png(file("pic.png"), image);
    const auto in = OIIO::ImageInput::open(file("pic.png").string());
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_STREQ(in->format_name(), "png");
    ASSERT_EQ(in->spec().width, 3);
    ASSERT_EQ(in->spec().height, 2);
    ASSERT_EQ(in->spec().nchannels, 3);
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
    std::vector<uint8_t> bytes(image.rgb.size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, bytes.data()));
    EXPECT_EQ(bytes, image.rgb);
}

TEST_F(ImageIo, LoadsAPngAsSrgbEncoded) {
    write_png(file("grey.png"), {1, 1, {128, 128, 128}});
    const LoadedImage loaded = load_image(file("grey.png"));
    EXPECT_EQ(loaded.input_colorspace, "sRGB");
    EXPECT_NEAR(loaded.image.pixels[0].g, 0.21586f, 1e-4f);
}

// --- atomic writes

TEST_F(ImageIo, WriteReplacesAnExistingFileAndLeavesNothingElse) {
    write_exr(file("out.exr"), RgbImage{1, 1, {{1, 1, 1}}});
    write_exr(file("out.exr"), RgbImage{1, 1, {{2, 2, 2}}});
    EXPECT_EQ(load_image(file("out.exr")).image.pixels[0].r, 2.0f);
    EXPECT_EQ(folder_entries(dir_), std::vector<std::string>{"out.exr"});
}

TEST_F(ImageIo, WriteIntoAMissingFolderFailsNamingTheDestination) {
    const fs::path destination = file("missing") / "out.exr";
    expect_image_error([&] { write_exr(destination, RgbImage{1, 1, {{1, 1, 1}}}); }, {destination.string()});
    EXPECT_TRUE(folder_entries(dir_).empty());
}

TEST_F(ImageIo, AFailedRenameRemovesTheTemporaryFile) {
    // A non-empty folder cannot be replaced by a file, so the rename fails after the write.
    fs::create_directories(file("taken.exr"));
    std::ofstream(file("taken.exr") / "keep") << "x";
    EXPECT_THROW(write_exr(file("taken.exr"), RgbImage{1, 1, {{1, 1, 1}}}), ImageError);
    EXPECT_THROW(write_png(file("taken.exr"), {1, 1, {1, 2, 3}}), ImageError);
    EXPECT_EQ(folder_entries(dir_), std::vector<std::string>{"taken.exr"});
    EXPECT_EQ(folder_entries(file("taken.exr")), std::vector<std::string>{"keep"});
}

TEST_F(ImageIo, WritingAnImageWhosePixelsDoNotMatchItsSizeFails) {
    EXPECT_THROW(write_exr(file("a.exr"), RgbImage{2, 2, RgbPixels(3)}), ImageError);
    EXPECT_THROW(write_exr(file("a.exr"), RgbImage{0, 0, {}}), ImageError);
    EXPECT_THROW(write_png(file("a.png"), {2, 1, {1, 2, 3}}), ImageError);
    EXPECT_TRUE(folder_entries(dir_).empty());
}

// --- unreadable files

TEST_F(ImageIo, AMissingFileIsAnErrorNamingIt) {
    expect_image_error([&] { load_image(file("nothing.exr")); }, {"nothing.exr", "no such file"});
}

TEST_F(ImageIo, AFolderIsAnErrorNamingIt) {
    fs::create_directories(file("folder.exr"));
    expect_image_error([&] { load_image(file("folder.exr")); }, {"folder.exr", "directory"});
}

TEST_F(ImageIo, ATextFileIsNotAnImage) {
    std::ofstream(file("x.exr")) << "This is not an image.\n";
    expect_image_error([&] { load_image(file("x.exr")); }, {"x.exr", "not a readable image"});
}

TEST_F(ImageIo, ATruncatedExrIsAnErrorNamingIt) {
    write_pattern(file("cut.exr"), "openexr", 64, 64, 3);
    fs::resize_file(file("cut.exr"), fs::file_size(file("cut.exr")) / 2);
    expect_image_error([&] { load_image(file("cut.exr")); }, {"cut.exr"});
}

TEST_F(ImageIo, ATruncatedPfmIsAnErrorNamingIt) {
    write_pfm(file("cut.pfm"), 8, 8, pattern(8, 8, 3));
    fs::resize_file(file("cut.pfm"), fs::file_size(file("cut.pfm")) / 2);
    expect_image_error([&] { load_image(file("cut.pfm")); }, {"cut.pfm", "truncated"});
}

TEST_F(ImageIo, AnImageWithoutPixelsIsAnErrorNamingIt) {
    std::ofstream(file("empty.pfm"), std::ios::binary) << "PF\n0 0\n-1.0\n";
    expect_image_error([&] { load_image(file("empty.pfm")); }, {"empty.pfm"});
}

// --- real maps, when ../shared/data/envmaps is beside the checkout

TEST(SharedMaps, AllLoadAsRgbAt1024x512AndNegativeExrValuesAreKept) {
    const fs::path dir = ENVMIS_SHARED_MAPS;
    if (!fs::is_directory(dir)) GTEST_SKIP() << dir << " not found";
    const char* maps[] = {"rooitou_park_1k.hdr",
                          "kloofendal_overcast_1k.hdr",
                          "potsdamer_platz_1k.hdr",
                          "lebombo_1k.hdr",
                          "empty_warehouse_01_1k.hdr",
                          "studio_small_03_1k.hdr",
                          "dikhololo_night_1k.hdr",
                          "city.exr",
                          "interior.exr",
                          "night.exr",
                          "studio.exr",
                          "pedestrian_overpass_1k.hdr",
                          "esplanade.hdr",
                          "st_fagans_interior_1k.hdr"};
    for (const char* name : maps) {
        const LoadedImage loaded = load_image(dir / name);
        EXPECT_EQ(loaded.image.width, 1024u) << name;
        EXPECT_EQ(loaded.image.height, 512u) << name;
        EXPECT_EQ(loaded.channels, 3u) << name;
        EXPECT_EQ(loaded.input_colorspace, "lin_rec709") << name;
        if (fs::path(name).extension() != ".exr") continue;
        // DWAB compression leaves small negatives; clamping them is EnvMap's job, not the loader's.
        size_t negative = 0;
        for (const Rgb& p : loaded.image.pixels) negative += (p.r < 0) + (p.g < 0) + (p.b < 0);
        EXPECT_GT(negative, 0u) << name;
    }
}

}  // namespace
}  // namespace envmis::io
