// envmis convert IN -o OUT.exr --to equal-area|equirect --size N|WxH: remaps an
// environment image to another mapping, conserving power (remap.h).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli.h"
#include "envmis/image/remap.h"
#include "envmis/io/image_io.h"

namespace envmis::cli {

Subcommand add_convert(CLI::App& app) {
    struct Args {
        std::string input, output, from = "equirect", to = "equal-area", size, colorspace, working_space = "lin_rec709";
        uint32_t supersampling = 0;
    };
    auto args = std::make_shared<Args>();
    CLI::App* sub =
        app.add_subcommand("convert",
                           "Remap an environment image between equirect and equal-area octahedral (pbrt-v4) mappings, "
                           "conserving power");
    sub->add_option("input", args->input, "HDR image")->required();
    sub->add_option("-o,--output", args->output, "OpenEXR file to write (float RGB)")->required();
    const auto mappings = CLI::IsMember({"equirect", "equal-area"});
    sub->add_option("--from", args->from, "Mapping of the input")->capture_default_str()->check(mappings);
    sub->add_option("--to", args->to, "Mapping of the output")->capture_default_str()->check(mappings);
    sub->add_option(
        "--size", args->size,
        "Output size: N (equal-area N x N, equirect 2N x N) or WxH (default: about the input's texel count)");
    sub->add_option("--supersampling", args->supersampling,
                    "Sub-samples per input texel side (default 0: automatic, at least 16 per output texel)")
        ->check(CLI::Range(0u, 64u));
    sub->add_option("--colorspace", args->colorspace, "Input colour space (default: from the file's metadata)");
    sub->add_option("--working-space", args->working_space, "Colour space of the output")->capture_default_str();
    return {sub, [args] {
                const Mapping from = parse_mapping(args->from), to = parse_mapping(args->to);
                io::LoadedImage image = io::load_image(args->input, {args->colorspace, args->working_space});
                uint32_t w = 0, h = 0;
                if (args->size.empty()) {
                    // The same number of texels, rounded to a power of two on the short side.
                    const double texels = static_cast<double>(image.image.width) * image.image.height;
                    const double side = to == Mapping::equal_area ? std::sqrt(texels) : std::sqrt(texels / 2);
                    h = 1u << static_cast<uint32_t>(std::lround(std::log2(std::max(side, 1.0))));
                    w = to == Mapping::equal_area ? h : 2 * h;
                } else {
                    unsigned a = 0, b = 0;
                    char x = 0;
                    const int n = std::sscanf(args->size.c_str(), "%u%c%u", &a, &x, &b);
                    if (n == 1 && a > 0) {
                        h = a;
                        w = to == Mapping::equal_area ? a : 2 * a;
                    } else if (n == 3 && x == 'x' && a > 0 && b > 0) {
                        w = a, h = b;
                    } else {
                        throw std::runtime_error("--size '" + args->size + "': expected N or WxH");
                    }
                }
                const auto start = std::chrono::steady_clock::now();
                const RemapResult result = remap(image.image, from, to, w, h, args->supersampling);
                const double ms = milliseconds_since(start);
                io::write_exr(args->output, result.image);
                const auto p_in = total_power(image.image, from), p_out = total_power(result.image, to);
                std::printf("%s (%ux%u %s) -> %s (%ux%u %s), %s, %u x %u sub-samples per input texel, %.0f ms\n",
                            args->input.c_str(), image.image.width, image.image.height, args->from.c_str(),
                            args->output.c_str(), w, h, args->to.c_str(), image.working_colorspace.c_str(),
                            result.supersampling, result.supersampling, ms);
                std::printf("power (sum of radiance x solid angle, R G B): in %.6g %.6g %.6g, out %.6g %.6g %.6g\n",
                            p_in[0], p_in[1], p_in[2], p_out[0], p_out[1], p_out[2]);
                if (result.bad_pixels.total())
                    std::printf("bad pixels: %llu NaN, %llu Inf, %llu negative channel values (replaced by 0)\n",
                                static_cast<unsigned long long>(result.bad_pixels.nan),
                                static_cast<unsigned long long>(result.bad_pixels.infinite),
                                static_cast<unsigned long long>(result.bad_pixels.negative));
            }};
}

}  // namespace envmis::cli
