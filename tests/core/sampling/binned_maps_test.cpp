// The binned sampler (binned.h) on the bundled real maps, downsampled to 128 x 64 so that
// a chi-square over every texel stays quick: the same checks as binned_test.cpp makes on
// synthetic maps (goodness of fit for normals at bin centres, borders and poles, pdf
// normalisation, coverage across bin borders).
#include <gtest/gtest.h>

#include <string>

#include "binned_checks.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/io/image_io.h"
#include "envmis/study/comparison/alpha.h"

namespace envmis {
namespace {

class BinnedMaps : public ::testing::TestWithParam<const char*> {
protected:
    static BinnedEnvMap load(const char* file) {
        const io::LoadedImage image = io::load_image(std::string(ENVMIS_DATA_DIR) + "/envmaps/" + file);
        EnvMapOptions options;
        options.compensation.enabled = false;
        options.luma = image.luma;
        return build_bins(build_env_map(downsample(image.image, 128), options));
    }
};

TEST_P(BinnedMaps, SamplesFollowTheirPdfAndThePdfIntegratesToOne) {
    const BinnedEnvMap map = load(GetParam());
    const BinnedEnvMapView view = map.view();
    uint64_t seed = 500;
    for (uint32_t lobe : {0u, 2u})  // each class on its own grid's centres and borders
        for (Vec3 n : test::test_normals(map.layout().side(lobe))) {
            test::expect_samples_follow_pdf(map, {n}, lobe, ++seed);
            EXPECT_NEAR(test::sphere_integral(256, 512, [&](Vec3 d) { return view.pdf({n}, lobe, 0.5f, d); }), 1.0,
                        1e-3);
        }
}

TEST_P(BinnedMaps, PdfCoversWhatEveryNormalOfTheBinSeesAcrossBinBorders) {
    const BinnedEnvMap map = load(GetParam());
    for (uint32_t lobe = 0; lobe < map.classes(); ++lobe) test::expect_coverage(map, lobe);
}

INSTANTIATE_TEST_SUITE_P(Bundled, BinnedMaps, ::testing::Values("rooitou_park_1k.hdr", "city.exr"),
                         [](const auto& info) { return std::string(info.param).substr(0, 4); });

}  // namespace
}  // namespace envmis
