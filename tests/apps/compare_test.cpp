// Specification of `envmis compare` against an independent exact computation: the
// variances it reports for one shading point agree, within statistical error, with
// quadrature over the map (quadrature.h), which shares no code with the estimators'
// sampling.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "envmis/io/image_io.h"
#include "envmis/study/reference/quadrature.h"
#include "maps.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;

TEST(Compare, SinglePointVariancesMatchTheExactVariances) {
    const fs::path dir = fs::temp_directory_path() / "envmis_compare_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const RgbImage image = test::random_map(64, 32, 21, 2);
    io::write_exr(dir / "map.exr", image);
    const std::string command = std::string(ENVMIS_CLI) + " compare " + (dir / "map.exr").string() +
                                " --normal 0.2,-0.3,1 --view 0.6,0.1,1 --bsdf lambert,phong:20 --spp 200000 --threads 2"
                                " --techniques env,bsdf,mis-balance,mis-power,mis-balance-comp --json " +
                                (dir / "r.json").string() + " > " + (dir / "out.txt").string();
    ASSERT_EQ(std::system(command.c_str()), 0);
    const nlohmann::json results = nlohmann::json::parse(std::ifstream(dir / "r.json"));

    EnvMapOptions plain_options;
    plain_options.compensation.enabled = false;
    const EnvMap plain(image, plain_options), compensated(image);
    const ShadingPoint point{normalize(Vec3{0.2f, -0.3f, 1}), normalize(Vec3{0.6f, 0.1f, 1})};
    ASSERT_EQ(results["results"].size(), 10u);
    for (const auto& r : results["results"]) {
        const Technique t = Technique::parse(r["technique"].get<std::string>());
        const double exact = exact_variance(t.compensated ? compensated : plain, t, {},
                                            Bsdf::parse(r["bsdf"].get<std::string>()), point, 8);
        // 200000 estimates of a map spanning two decades: the sample variance is within a
        // few percent; 8% is several of its standard errors.
        EXPECT_NEAR(r["variance"].get<double>(), exact, 0.08 * exact) << r["bsdf"] << " " << r["technique"];
        EXPECT_NEAR(r["mean"].get<double>(), r["reference"].get<double>(), 4 * r["std_error"].get<double>())
            << r["bsdf"] << " " << r["technique"];
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace envmis
