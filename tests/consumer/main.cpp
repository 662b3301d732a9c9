// An installed envmis, used as a renderer and a table maker would. Exits non-zero, saying
// why, on any mismatch.
//
// Usage: consumer_build|consumer_io WORK_FOLDER
//        consumer_core WORK_FOLDER TABLE
// consumer_build (envmis::core and envmis::build) builds a sampler from an image, saves it
// as WORK_FOLDER/sky.envmis, loads it back and samples it. consumer_core (envmis::core
// alone, a renderer) loads TABLE, the table consumer_build wrote, copied and mapped: it
// must hold the same sky, and both loads must sample alike. consumer_io also writes the
// image as EXR, loads it through OpenImageIO and OpenColorIO ($OCIO: the installed
// config) and samples that.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "envmis/core.h"
#ifdef ENVMIS_CONSUMER_BUILD
#include "envmis/build.h"
#endif
#ifdef ENVMIS_CONSUMER_IO
#include "envmis/io/colour.h"
#include "envmis/io/image_io.h"
#endif

namespace {

void check(bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(what);
}

// A sky brightening towards the zenith with a small bright sun: compensation zeroes
// part of it, so the sampler's density is far from uniform.
envmis::RgbImage sky(uint32_t w, uint32_t h) {
    envmis::RgbImage image{w, h, envmis::RgbPixels(size_t{w} * h)};
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float l = 0.2f + 0.8f * (1.0f - static_cast<float>(y) / static_cast<float>(h));
            image.pixels[size_t{y} * w + x] = {0.6f * l, 0.8f * l, 1.2f * l};
        }
    image.pixels[size_t{h / 4} * w + w / 3] = {5000, 5000, 5000};
    return image;
}

// The pdf is a density over the sphere: summed over texel centres times texel solid
// angles it must give 1.
void check_normalised(const envmis::EnvMap& map) {
    const uint32_t w = map.width(), h = map.height();
    double total = 0;
    for (uint32_t y = 0; y < h; ++y) {
        const double v = (y + 0.5) / h;
        const double texel_solid_angle =
            2 * envmis::kPi * envmis::kPi * std::sin(envmis::kPi * v) / (static_cast<double>(w) * h);
        for (uint32_t x = 0; x < w; ++x)
            total += map.pdf_uv({static_cast<float>((x + 0.5) / w), static_cast<float>(v)}) * texel_solid_angle;
    }
    check(std::abs(total - 1) < 1e-3, "pdf integrates to " + std::to_string(total) + ", not 1");
}

// Samples must carry their own pdf, agree with pdf(direction) and be reproduced
// bit-identically by the loaded copy. pdf(direction) rounds the direction back to the
// image, which can cross into the next texel for a sample on a texel's edge: a few of
// those are allowed.
void check_samples(const envmis::EnvMap& map, const envmis::EnvMap& loaded) {
    uint64_t state = 0x9e3779b97f4a7c15ull;
    auto uniform = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<float>(state >> 40) * 0x1p-24f;
    };
    const int n = 10000;
    int edge_cases = 0;
    for (int i = 0; i < n; ++i) {
        const envmis::Vec2 u{uniform(), uniform()};
        const envmis::EnvSample s = map.sample(u), t = loaded.sample(u);
        const std::string at = "sample " + std::to_string(i);
        check(s.pdf > 0 && std::isfinite(s.pdf), at + ": pdf " + std::to_string(s.pdf));
        check(std::abs(envmis::length(s.direction) - 1) < 1e-5f, at + ": direction is not a unit vector");
        check(map.pdf_uv(s.uv) == s.pdf, at + ": pdf_uv(uv) differs from the sample's pdf");
        check(t.pdf == s.pdf && t.uv.x == s.uv.x && t.uv.y == s.uv.y, at + ": the loaded table samples differently");
        edge_cases += std::abs(map.pdf(s.direction) - s.pdf) > 1e-3f * s.pdf;
    }
    check(edge_cases < n / 500,
          std::to_string(edge_cases) + " of " + std::to_string(n) + " samples disagree with pdf(direction)");
}

const envmis::TableSource kSource{"sky.exr", 42, "lin_rec709", "lin_rec709", ""};

// The table `table_file` holds `map`.
void check_table(const envmis::EnvMap& map, const std::filesystem::path& table_file) {
    const envmis::TableSource& source = kSource;
    check(envmis::looks_like_table(table_file), "the written table is not recognised");
    const envmis::Table table = envmis::read_table(table_file);
    check(table.map.width() == map.width() && table.map.height() == map.height(), "loaded size differs");
    check(table.source.name == source.name && table.source.content_hash == source.content_hash,
          "loaded source differs");
    check(table.map.compensated() == map.compensated(), "loaded density kind differs");
    check_normalised(table.map);
    check_samples(map, table.map);
}

#ifdef ENVMIS_CONSUMER_BUILD
void check_map(const envmis::EnvMap& map, const std::filesystem::path& table_file) {
    envmis::write_table(table_file, map, kSource);
    check_table(map, table_file);
}
#endif

}  // namespace

int main(int argc, char** argv) {
#ifdef ENVMIS_CONSUMER_BUILD
    const int args = 2;
#else
    const int args = 3;
#endif
    if (argc != args) {
        std::fprintf(stderr, "usage: %s WORK_FOLDER%s\n", argv[0], args == 3 ? " TABLE" : "");
        return 2;
    }
    try {
        const std::filesystem::path work = argv[1];
        std::filesystem::create_directories(work);
#ifdef ENVMIS_CONSUMER_BUILD
        const envmis::EnvMap map = envmis::build_env_map(sky(64, 32));
        check(map.compensated() && !map.complete(), "the synthetic sky should be compensated and incomplete");
        check_map(map, work / "sky.envmis");
#else
        const envmis::EnvMap map = envmis::read_table(argv[2], envmis::TableLoading::copy).map;
        const envmis::RgbImage expected = sky(64, 32);
        check(map.width() == expected.width && map.height() == expected.height, "the table is not the sky's size");
        for (size_t i = 0; i < expected.pixels.size(); ++i)
            check(map.radiance().pixels[i].r == expected.pixels[i].r &&
                      map.radiance().pixels[i].b == expected.pixels[i].b,
                  "the table's radiance is not the sky's at texel " + std::to_string(i));
        check(map.compensated() && !map.complete(), "the synthetic sky should be compensated and incomplete");
        check_table(map, argv[2]);
#endif
#ifdef ENVMIS_CONSUMER_IO
        const envmis::io::ColourConfig config;
        check(config.has_space("lin_rec709"), "the OCIO config " + config.description() + " lacks lin_rec709");
        envmis::io::write_exr(work / "sky.exr", map.radiance());
        const envmis::io::LoadedImage loaded = envmis::io::load_image(work / "sky.exr");
        check(loaded.image.pixels.size() == map.radiance().pixels.size(), "the EXR round trip changed the size");
        check(loaded.image.pixels[0].g == map.radiance().pixels[0].g, "the EXR round trip changed the pixels");
        envmis::EnvMapOptions options;
        options.luma = loaded.luma;
        check_map(envmis::build_env_map(loaded.image, options), work / "sky_from_exr.envmis");
#endif
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
        return 1;
    }
    std::printf("%s: ok\n", argv[0]);
    return 0;
}
