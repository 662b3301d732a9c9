// Writes a few small valid tables into a folder: the seed corpus for envmis_table_fuzz.
// Small maps keep each fuzz iteration fast; the variants cover both density kinds, a
// non-default frame and a fallback, so the fuzzer starts from every branch of the reader.
#include <cstdio>
#include <exception>
#include <filesystem>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/build/table_writer.h"

namespace {

// A gradient with one bright texel, so that compensation zeroes part of the map.
envmis::RgbImage sky(uint32_t w, uint32_t h) {
    envmis::RgbImage image{w, h, envmis::RgbPixels(size_t{w} * h)};
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float l = 0.1f + static_cast<float>(x + 2 * y) / static_cast<float>(w + 2 * h);
            image.pixels[size_t{y} * w + x] = {0.5f * l, l, 1.5f * l};
        }
    image.pixels[w / 2] = {100, 90, 80};
    return image;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
        return 2;
    }
    try {
        const std::filesystem::path dir = argv[1];
        std::filesystem::create_directories(dir);
        const envmis::TableSource source{"seed.exr", 0x1234, "lin_rec709", "lin_rec709", ""};

        envmis::write_table(dir / "compensated_4x2.envmis", envmis::build_env_map(sky(4, 2)), source);

        envmis::EnvMapOptions plain;
        plain.compensation.enabled = false;
        plain.axes = envmis::Axes::parse("y-up");
        envmis::write_table(dir / "uncompensated_16x8.envmis", envmis::build_env_map(sky(16, 8), plain), source);

        // A bins section, after a full and after a compact payload.
        envmis::BinnedOptions bins;
        bins.bins_per_side = 2;
        bins.cell_columns = 4;
        const envmis::BinnedEnvMap binned = envmis::build_bins(envmis::build_env_map(sky(16, 8), plain), bins);
        envmis::write_table(dir / "binned_16x8.envmis", binned, source);
        envmis::write_table(dir / "binned_compact_16x8.envmis", binned, source, envmis::TableEncoding::compact);

        // A black map: the uniform fallback.
        envmis::RgbImage black{8, 4, envmis::RgbPixels(32)};
        envmis::write_table(dir / "black_8x4.envmis", envmis::build_env_map(black), source);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "envmis_make_fuzz_seed: %s\n", e.what());
        return 1;
    }
    return 0;
}
