// envmis convert IN -o OUT.exr --to equal-area|equirect --size N|WxH: remaps an
// environment image to another mapping, conserving power (remap.h).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "cli.h"
#include "envmis/build/remap.h"
#include "envmis/io/image_io.h"

namespace envmis::cli {
namespace {

// The arguments of `envmis convert`.
struct ConvertArgs {
    std::string input, output, from = "equirect", to = "equal-area", size, colorspace, working_space = "lin_rec709";
    uint32_t supersampling = 0;
};

void add_convert_flags(CLI::App& sub, ConvertArgs& args) {
    sub.add_option("input", args.input, "HDR image")->required();
    sub.add_option("-o,--output", args.output, "OpenEXR file to write (float RGB)")
        ->required()
        ->check(output_extension(".exr", "OpenEXR"));
    const auto mappings = CLI::IsMember({"equirect", "equal-area"});
    sub.add_option("--from", args.from, "Mapping of the input")->capture_default_str()->check(mappings);
    sub.add_option("--to", args.to, "Mapping of the output")->capture_default_str()->check(mappings);
    sub.add_option("--size", args.size,
                   "Output size: N (equal-area N x N, equirect 2N x N) or WxH, each side 1 to 65536, at most 2^31 "
                   "texels and about 24 bytes a texel of free memory (default: the input's texel count, the short side "
                   "rounded to a power of two: between half and twice the texels; 1024x512 to equal-area gives 1024)")
        ->type_name("N|WxH")
        ->check(size_validator(true));
    sub.add_option("--supersampling", args.supersampling,
                   "Sub-samples per input texel side (default 0: automatic, at least 16 per output texel)")
        ->check(in_range(uint32_t{0}, uint32_t{64}));
    sub.add_option("--colorspace", args.colorspace, "Input colour space (default: from the file's metadata)");
    sub.add_option("--working-space", args.working_space, "Colour space of the output")->capture_default_str();
}

// What an output texel costs at the peak: remap's accumulator (power and solid angle, 4
// doubles) beside the remapped image, then the image and the writer's encoded copy.
constexpr uint64_t kBytesPerTexel = 4 * sizeof(double) + 2 * sizeof(Rgb);

// The output size --size asks for (checked before any work), or 0 x 0 for the default.
Size requested_size(const std::string& text, Mapping to) {
    if (text.empty()) return {};
    const Size size = *parse_size(text, true);  // the flag's validator has accepted it
    if (size.height != 0) return size;
    if (to == Mapping::equal_area) return {size.width, size.width};
    if (size.width > kMaxCells1D / 2)
        throw UsageError("--size " + text + ": an equirect output is 2N x N, N at most " +
                         std::to_string(kMaxCells1D / 2));
    return {2 * size.width, size.width};
}

// About the input's texel count, rounded to a power of two on the short side.
Size default_size(const RgbImage& image, Mapping to) {
    const double texels = static_cast<double>(image.width) * image.height;
    const double side = to == Mapping::equal_area ? std::sqrt(texels) : std::sqrt(texels / 2);
    const uint32_t h = 1u << static_cast<uint32_t>(std::lround(std::log2(std::max(side, 1.0))));
    return {to == Mapping::equal_area ? h : 2 * h, h};
}

void print_conversion(const ConvertArgs& args, const io::LoadedImage& image, const RemapResult& result, double ms) {
    const Mapping from = parse_mapping(args.from), to = parse_mapping(args.to);
    const auto p_in = total_power(image.image, from), p_out = total_power(result.image, to);
    std::printf("%s (%ux%u %s) -> %s (%ux%u %s), %s, %u x %u sub-samples per input texel, %.0f ms\n",
                args.input.c_str(), image.image.width, image.image.height, args.from.c_str(), args.output.c_str(),
                result.image.width, result.image.height, args.to.c_str(), image.working_colorspace.c_str(),
                result.supersampling, result.supersampling, ms);
    std::printf("power (sum of radiance x solid angle, R G B): in %.6g %.6g %.6g, out %.6g %.6g %.6g\n", p_in[0],
                p_in[1], p_in[2], p_out[0], p_out[1], p_out[2]);
    if (result.bad_pixels.total())
        std::printf("bad pixels: %llu NaN, %llu Inf, %llu negative channel values (replaced by 0)\n",
                    static_cast<unsigned long long>(result.bad_pixels.nan),
                    static_cast<unsigned long long>(result.bad_pixels.infinite),
                    static_cast<unsigned long long>(result.bad_pixels.negative));
}

void run_convert(const ConvertArgs& args) {
    check_outputs({args.input}, {{"-o", args.output}});
    prepare_output(args.output);
    const Mapping from = parse_mapping(args.from), to = parse_mapping(args.to);
    Size size = requested_size(args.size, to);
    if (size.width != 0) check_image_size("--size " + args.size, size, kBytesPerTexel);
    check_map_memory(args.input, 2 * sizeof(Rgb));  // the pixels read and the map
    const io::LoadedImage image = io::load_image(args.input, {args.colorspace, args.working_space, &interrupted()});
    for (const std::string& notice : image.notices) std::cerr << "note: " << printable(notice) << "\n";
    if (size.width == 0) {
        size = default_size(image.image, to);
        check_image_size(args.input + ": output of " + std::to_string(size.width) + "x" + std::to_string(size.height),
                         size, kBytesPerTexel);
    }
    const auto start = std::chrono::steady_clock::now();
    std::optional<Progress> progress(std::in_place, "remapping", 1);
    const RemapResult result =
        remap(image.image, from, to, size.width, size.height, args.supersampling, &interrupted());
    progress.reset();
    const double ms = milliseconds_since(start);
    io::write_exr(args.output, result.image);
    print_conversion(args, image, result, ms);
}

}  // namespace

Subcommand add_convert(CLI::App& app) {
    auto args = std::make_shared<ConvertArgs>();
    CLI::App* sub =
        app.add_subcommand("convert",
                           "Remap an environment image between equirect and equal-area octahedral (pbrt-v4) mappings, "
                           "conserving power");
    add_convert_flags(*sub, *args);
    add_threads_flag(*sub);
    return {sub, [args] { run_convert(*args); }};
}

}  // namespace envmis::cli
