// Specification of colour spaces (colour.h) and of the shipped OCIO config.
#include "envmis/io/colour.h"

#include <OpenColorIO/OpenColorIO.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "envmis/io/image_io.h"
#include "errors.h"

namespace envmis::io {
namespace {

namespace fs = std::filesystem;

const fs::path kShippedConfig = fs::path(ENVMIS_DATA_DIR) / "ocio" / "config.ocio";

// Sets or unsets an environment variable for the lifetime of the object.
class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        value ? setenv(name, value, 1) : unsetenv(name);
    }
    ~ScopedEnv() { old_ ? setenv(name_, old_->c_str(), 1) : unsetenv(name_); }

private:
    const char* name_;
    std::optional<std::string> old_;
};

// A config with one linear space and no XYZ space, written to a temporary file.
class TinyConfig {
public:
    TinyConfig() : path_(fs::temp_directory_path() / ("envmis_colour_test_" + std::to_string(getpid()) + ".ocio")) {
        std::ofstream(path_) << "ocio_profile_version: 2\n"
                                "luma: [0.3, 0.6, 0.1]\n"
                                "roles: {default: linear, scene_linear: linear}\n"
                                "file_rules: [!<Rule> {name: Default, colorspace: default}]\n"
                                "displays: {d: [!<View> {name: v, colorspace: linear}]}\n"
                                "colorspaces: [!<ColorSpace> {name: linear, isdata: false}]\n";
    }
    ~TinyConfig() { fs::remove(path_); }
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

template <class Action>
void expect_image_error(Action&& action, std::initializer_list<std::string> parts) {
    test::expect_error<ImageError>(std::forward<Action>(action), parts);
}

ColourConfig shipped() { return ColourConfig(kShippedConfig); }

std::vector<Rgb> converted(std::vector<Rgb> pixels, const std::string& from, const std::string& to) {
    shipped().convert(pixels, from, to);
    return pixels;
}

void expect_luma_near(LumaCoefficients k, float r, float g, float b, float tolerance) {
    EXPECT_NEAR(k.r, r, tolerance);
    EXPECT_NEAR(k.g, g, tolerance);
    EXPECT_NEAR(k.b, b, tolerance);
}

TEST(ShippedConfig, IsAValidOcioVersion2Config) {
    OCIO_NAMESPACE::ConstConfigRcPtr config;
    ASSERT_NO_THROW(config = OCIO_NAMESPACE::Config::CreateFromFile(kShippedConfig.c_str()));
    EXPECT_EQ(config->getMajorVersion(), 2u);
    EXPECT_NO_THROW(config->validate());
}

TEST(ShippedConfig, DefinesTheDocumentedSpaces) {
    const ColourConfig config = shipped();
    const std::vector<std::string> spaces = config.spaces();
    for (const char* name : {"lin_rec709", "ACEScg", "ACES2065-1", "sRGB", "CIE-XYZ-D65", "raw"}) {
        EXPECT_TRUE(config.has_space(name)) << name;
        EXPECT_NE(std::find(spaces.begin(), spaces.end(), name), spaces.end()) << name;
    }
}

TEST(ShippedConfig, SceneLinearAndDataRolesAreLinRec709AndRaw) {
    EXPECT_EQ(shipped().resolve("scene_linear"), "lin_rec709");
    EXPECT_EQ(shipped().resolve("data"), "raw");
}

TEST(ColourConfig, ResolvesFileMetadataNamesCaseInsensitively) {
    const ColourConfig config = shipped();
    const std::pair<const char*, const char*> cases[] = {
        {"Linear", "lin_rec709"},   {"linear", "lin_rec709"},     {"scene_linear", "lin_rec709"},
        {"lin_srgb", "lin_rec709"}, {"LIN_REC709", "lin_rec709"}, {"sRGB", "sRGB"},
        {"srgb", "sRGB"},           {"sRGB - Texture", "sRGB"},   {"ACEScg", "ACEScg"},
        {"acescg", "ACEScg"},       {"lin_ap1", "ACEScg"},        {"ACES - ACES2065-1", "ACES2065-1"},
        {"XYZ", "CIE-XYZ-D65"},
    };
    for (const auto& [metadata, canonical] : cases) EXPECT_EQ(config.resolve(metadata), canonical) << metadata;
}

TEST(ColourConfig, ResolvesUnknownNamesToEmpty) {
    const ColourConfig config = shipped();
    EXPECT_EQ(config.resolve(""), "");
    EXPECT_EQ(config.resolve("no_such_space"), "");
    EXPECT_FALSE(config.has_space("no_such_space"));
}

// OpenImageIO's PNM reader tags both linear PFM and encoded PPM files "Rec709", so the
// tag says nothing about the encoding and must not resolve.
TEST(ColourConfig, LeavesOpenImageIOsAmbiguousRec709TagUnresolved) { EXPECT_EQ(shipped().resolve("Rec709"), ""); }

TEST(ColourConfig, LumaOfLinRec709IsExactlyBt709) {
    expect_luma_near(shipped().luma("lin_rec709"), 0.2126f, 0.7152f, 0.0722f, 1e-7f);
}

// Luma is the Y row of the conversion to CIE XYZ D65, which for ACEScg includes the
// Bradford adaptation from the ACES white. It differs by about 0.005 from the Y row of
// AP1's own (D60) RGB->XYZ matrix, (0.2722, 0.6741, 0.0537).
TEST(ColourConfig, LumaOfAcescgIsTheYRowOfItsConversionToXyzD65) {
    const LumaCoefficients k = shipped().luma("ACEScg");
    expect_luma_near(k, 0.2677f, 0.6743f, 0.0580f, 1e-3f);
    EXPECT_NEAR(k.r + k.g + k.b, 1.0f, 1e-5f);
}

TEST(ColourConfig, LuminanceDoesNotDependOnTheWorkingSpace) {
    const std::vector<Rgb> rec709 = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.3f, 2.0f, 0.05f}, {1e4f, 5e3f, 2e3f}};
    const std::vector<Rgb> acescg = converted(rec709, "lin_rec709", "ACEScg");
    const LumaCoefficients k709 = shipped().luma("lin_rec709"), kcg = shipped().luma("ACEScg");
    for (size_t i = 0; i < rec709.size(); ++i) {
        const float expected = luminance(rec709[i], k709);
        // Up to the rounding of BT.709's published weights (0.2126 for 0.212639, ...).
        EXPECT_NEAR(luminance(acescg[i], kcg), expected, 3e-4f * std::max(1.0f, expected)) << i;
    }
}

TEST(ColourConfig, LumaOfADataSpaceIsTheConfigDefault) {
    expect_luma_near(shipped().luma("raw"), 0.2126f, 0.7152f, 0.0722f, 1e-6f);
}

TEST(ColourConfig, LumaFallsBackToTheConfigDefaultWithoutAnXyzSpace) {
    const TinyConfig tiny;
    expect_luma_near(ColourConfig(tiny.path()).luma("linear"), 0.3f, 0.6f, 0.1f, 1e-6f);
}

TEST(ColourConfig, LumaOfAnUnknownSpaceIsAnErrorNamingIt) {
    expect_image_error([] { shipped().luma("no_such_space"); }, {"'no_such_space'"});
}

TEST(ColourConfig, ConvertsRec709PrimariesToAcescgWithTheStandardMatrix) {
    const auto ap1 = converted({{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, "lin_rec709", "ACEScg");
    const float expected[3][3] = {
        {0.6131f, 0.0702f, 0.0206f}, {0.3395f, 0.9164f, 0.1096f}, {0.0474f, 0.0135f, 0.8698f}};
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(ap1[i].r, expected[i][0], 1e-4f) << i;
        EXPECT_NEAR(ap1[i].g, expected[i][1], 1e-4f) << i;
        EXPECT_NEAR(ap1[i].b, expected[i][2], 1e-4f) << i;
    }
}

TEST(ColourConfig, AcescgRoundTripReturnsTheInputWithin1e5) {
    const std::vector<Rgb> input = {
        {0.18f, 0.18f, 0.18f}, {1, 0, 0}, {0.02f, 0.7f, 0.3f}, {0, 0, 1}, {0.5f, 0.25f, 0.9f}};
    const auto back = converted(converted(input, "lin_rec709", "ACEScg"), "ACEScg", "lin_rec709");
    for (size_t i = 0; i < input.size(); ++i) {
        EXPECT_NEAR(back[i].r, input[i].r, 1e-5f) << i;
        EXPECT_NEAR(back[i].g, input[i].g, 1e-5f) << i;
        EXPECT_NEAR(back[i].b, input[i].b, 1e-5f) << i;
    }
}

TEST(ColourConfig, DecodesSrgbWithTheStandardCurve) {
    const auto linear = converted({{0.5f, 1.0f, 0.0f}, {0.04045f, 0.2f, 0.8f}}, "sRGB", "lin_rec709");
    EXPECT_NEAR(linear[0].r, 0.21404f, 1e-4f);
    EXPECT_NEAR(linear[0].g, 1.0f, 1e-5f);
    EXPECT_NEAR(linear[0].b, 0.0f, 1e-7f);
    EXPECT_NEAR(linear[1].r, 0.04045f / 12.92f, 1e-5f);
    EXPECT_NEAR(linear[1].g, 0.03310f, 1e-4f);
    EXPECT_NEAR(linear[1].b, 0.60383f, 1e-4f);
}

TEST(ColourConfig, ConvertsRec709WhiteToXyzD65White) {
    const auto xyz = converted({{1, 1, 1}}, "lin_rec709", "CIE-XYZ-D65");
    EXPECT_NEAR(xyz[0].r, 0.95046f, 1e-4f);
    EXPECT_NEAR(xyz[0].g, 1.0f, 1e-5f);
    EXPECT_NEAR(xyz[0].b, 1.08906f, 1e-4f);
}

TEST(ColourConfig, ConvertingASpaceToItselfLeavesPixelsUntouched) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const std::vector<Rgb> input = {{nan, inf, -inf}, {-1, 0.1f, 1e30f}};
    const auto output = converted(input, "Linear", "lin_rec709");
    EXPECT_TRUE(std::isnan(output[0].r));
    EXPECT_EQ(output[0].g, inf);
    EXPECT_EQ(output[0].b, -inf);
    EXPECT_EQ(output[1].r, -1.0f);
    EXPECT_EQ(output[1].g, 0.1f);
    EXPECT_EQ(output[1].b, 1e30f);
}

TEST(ColourConfig, ConvertsImagesOfAnySizeUniformly) {
    const std::vector<Rgb> input(200'003, Rgb{0.25f, 0.5f, 0.75f});
    const auto output = converted(input, "lin_rec709", "ACEScg");
    const Rgb first = output.front();
    for (const Rgb& p : output) ASSERT_TRUE(p.r == first.r && p.g == first.g && p.b == first.b);
    EXPECT_NE(first.r, 0.25f);
}

TEST(ColourConfig, ConvertingFromOrToAnUnknownSpaceIsAnErrorNamingIt) {
    std::vector<Rgb> pixels(4);
    expect_image_error([&] { shipped().convert(pixels, "no_such_space", "lin_rec709"); }, {"'no_such_space'"});
    expect_image_error([&] { shipped().convert(pixels, "lin_rec709", "no_such_space"); }, {"'no_such_space'"});
}

TEST(ColourConfig, UsesTheConfigNamedByTheOcioVariable) {
    const TinyConfig tiny;
    const ScopedEnv env("OCIO", tiny.path().c_str());
    const ColourConfig config;
    EXPECT_NE(config.description().find(tiny.path().string()), std::string::npos) << config.description();
    EXPECT_NE(config.description().find("$OCIO"), std::string::npos) << config.description();
    EXPECT_EQ(config.spaces(), std::vector<std::string>{"linear"});
}

TEST(ColourConfig, UsesTheShippedConfigWhenOcioIsUnset) {
    const ScopedEnv env("OCIO", nullptr);
    const ColourConfig config;
    EXPECT_NE(config.description().find("config.ocio"), std::string::npos) << config.description();
    EXPECT_TRUE(config.has_space("ACEScg"));
}

TEST(ColourConfig, AnUnreadableConfigIsAnErrorNamingTheFile) {
    const fs::path missing = fs::temp_directory_path() / "envmis_no_such_config.ocio";
    expect_image_error([&] { ColourConfig{missing}; }, {missing.string()});
    const ScopedEnv env("OCIO", missing.c_str());
    expect_image_error([] { ColourConfig{}; }, {missing.string()});
}

}  // namespace
}  // namespace envmis::io
