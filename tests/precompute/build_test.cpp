#include "envmis/precompute/build.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace envmis {
namespace {

RgbImage grey(uint32_t width, uint32_t height) {
    return {width, height, RgbPixels(size_t{width} * height, Rgb{0.5f, 0.5f, 0.5f})};
}

TEST(CanonicalOptions, EveryFieldThatChangesTheTableChangesTheString) {
    const BuildRequest base;
    const std::string text = canonical_options(base);
    EXPECT_EQ(text,
              "compensate=1 alpha=1 mapping=equirect colorspace=(file) working-space=lin_rec709 axes=z-up compact=0 "
              "bins=0 cell-columns=0");
    const auto changed = [&](auto change) {
        BuildRequest request = base;
        change(request);
        return canonical_options(request);
    };
    EXPECT_NE(changed([](BuildRequest& r) { r.alpha = 2.0f; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.alpha_auto = true; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.compensate = false; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.axes = "y-up"; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.compact = true; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.bins = 9; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.colorspace = "ACEScg"; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.mapping = "equal-area"; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.working_space = "ACEScg"; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.cell_columns = 64; }), text);
    // The bins' cost matters only to bins.
    EXPECT_EQ(changed([](BuildRequest& r) { r.bin_cost = 3; }), text);
    EXPECT_NE(changed([](BuildRequest& r) { r.bins = 9, r.bin_cost = 3; }),
              changed([](BuildRequest& r) { r.bins = 9; }));
    // Each field is a field of its own: the same value in another is another string.
    EXPECT_NE(changed([](BuildRequest& r) { r.colorspace = "ACEScg"; }),
              changed([](BuildRequest& r) { r.working_space = "ACEScg"; }));
}

TEST(CanonicalOptions, RecordTheEffectiveAlphaNotHowItWasAskedFor) {
    BuildRequest given_one, defaulted;
    given_one.alpha = 1.0f;
    EXPECT_EQ(canonical_options(given_one), canonical_options(defaulted));
    // With bins, no alpha means a choice per bin.
    defaulted.bins = 9;
    EXPECT_NE(canonical_options(defaulted).find("alpha=auto"), std::string::npos);
    defaulted.compensate = false;
    EXPECT_NE(canonical_options(defaulted).find("alpha=-"), std::string::npos);
}

TEST(CanonicalOptions, ParseBackToARequestThatSpellsTheSame) {
    std::vector<BuildRequest> requests(6);
    requests[1].alpha = 0.1f, requests[1].compact = true;
    requests[2].alpha_auto = true, requests[2].axes = "x,z,-y";
    requests[3].compensate = false, requests[3].colorspace = "Utility - Linear - sRGB";
    requests[4].bins = 121, requests[4].bin_cost = 2.5f, requests[4].cell_columns = 64;
    requests[5].bins = 9, requests[5].alpha = 0.5f, requests[5].mapping = "equal-area";
    for (const BuildRequest& request : requests) {
        const std::string text = canonical_options(request);
        const std::optional<BuildRequest> parsed = parse_canonical_options(text);
        ASSERT_TRUE(parsed) << text;
        EXPECT_EQ(canonical_options(*parsed), text);
        EXPECT_EQ(parsed->compact, request.compact) << text;
        EXPECT_EQ(parsed->colorspace, request.colorspace) << text;
        EXPECT_EQ(parsed->bins, request.bins) << text;
    }
}

TEST(CanonicalOptions, RefuseToParseWhatIsNotACanonicalSpelling) {
    const std::string text = canonical_options(BuildRequest{});
    for (const std::string& other :
         {std::string(), std::string("compensate=1"), text + " extra=1", "x" + text,
          std::string("compensate=1 alpha=1 mapping=equirect colorspace=(file) working-space=lin_rec709 axes=z-up "
                      "compact=0"),  // an older table's, without bins
          std::string("compensate=1 alpha=01 mapping=equirect colorspace=(file) working-space=lin_rec709 axes=z-up "
                      "compact=0 bins=0 cell-columns=0"),
          std::string("compensate=1 alpha=1 mapping=equirect colorspace=(file) working-space=lin_rec709 axes=z-up "
                      "compact=2 bins=0 cell-columns=0"),
          std::string("compensate=1 alpha=1 mapping=equirect colorspace=(file) working-space=lin_rec709 axes=z-up "
                      "compact=0 bins=0 cell-columns=0 bin-cost=2")})
        EXPECT_FALSE(parse_canonical_options(other)) << other;
}

TEST(BuildRequestChecks, SayWhatTheCommandLineSays) {
    EXPECT_EQ(alpha_problem("auto"), "");
    EXPECT_EQ(alpha_problem("0.5"), "");
    EXPECT_EQ(alpha_problem("-1"), "'-1': expected a number >= 0 or auto");
    EXPECT_EQ(bins_problem("64"), "");
    EXPECT_EQ(bins_problem("5"),
              "5: expected a square number of bins (g x g octahedral grid) from 1 to 4096, such as 64, 100 or 144");
    BuildRequest request;
    request.cell_columns = 8;
    EXPECT_THROW(check(request), std::invalid_argument);
    request.bins = 8;
    try {
        check(request);
        FAIL() << "bins 8 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("bins: 8: expected a square number", 0), 0u) << e.what();
    }
    request.bins = 9, request.cell_columns = 0;
    for (float cost : {0.5f, 101.0f, std::nanf("")}) {
        request.bin_cost = cost;
        EXPECT_THROW(check(request), std::invalid_argument) << cost;
    }
}

TEST(BuildMap, RecordsTheCanonicalOptionsAndBuildsBinsWhereAsked) {
    BuildRequest request;
    request.bins = 9;
    request.alpha = 0.5f;
    const BuiltMap built = build_map(grey(64, 32), request);
    ASSERT_TRUE(built.binned.has_value());
    EXPECT_EQ(built.binned->bins(), 9u);
    EXPECT_FALSE(built.binned->radiance_map().compensated());
    EXPECT_EQ(built.source.build_options, canonical_options(request));
    EXPECT_EQ(built.source.name, "array");
    EXPECT_TRUE(built.notices.empty());
}

TEST(BuildMap, ReturnsTheSquareImageNoticeInsteadOfPrintingIt) {
    const BuiltMap built = build_map(grey(16, 16), BuildRequest{});
    ASSERT_EQ(built.notices.size(), 1u);
    EXPECT_EQ(built.notices.front().rfind("array is square; it is read as equirect", 0), 0u) << built.notices.front();
    BuildRequest equal_area;
    equal_area.mapping = "equal-area";
    EXPECT_THROW(build_map(grey(32, 16), equal_area), std::invalid_argument);
}

}  // namespace
}  // namespace envmis
