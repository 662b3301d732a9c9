#include "envmis/io/colour.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cstdlib>

#include "envmis/io/image_io.h"

namespace OCIO = OCIO_NAMESPACE;

namespace envmis::io {
namespace {

std::filesystem::path shipped_config() {
    for (const char* dir : {ENVMIS_SOURCE_DATA_DIR, ENVMIS_INSTALL_DATA_DIR}) {
        const auto file = std::filesystem::path(dir) / "ocio" / "config.ocio";
        std::error_code ec;
        if (std::filesystem::is_regular_file(file, ec)) return file;
    }
    throw ImageError("no OCIO config: $OCIO is unset and neither " ENVMIS_SOURCE_DATA_DIR
                     "/ocio/config.ocio nor " ENVMIS_INSTALL_DATA_DIR "/ocio/config.ocio exists");
}

}  // namespace

struct ColourConfig::Impl {
    OCIO::ConstConfigRcPtr config;
    std::string description;
    std::string xyz;  // a scene-referred CIE XYZ (D65) space; empty if the config has none

    Impl(const std::filesystem::path& file, std::string origin) : description(std::move(origin)) {
        try {
            config = OCIO::Config::CreateFromFile(file.c_str());
            config->validate();
        } catch (const OCIO::Exception& e) {
            throw ImageError("cannot load OCIO config " + file.string() + ": " + e.what());
        }
        // A display-referred XYZ (the ACES reference configs have one) would be reached through a
        // view transform, which tone-maps: useless for luma.
        if (auto cs = config->getColorSpace("CIE-XYZ-D65");
            cs && cs->getReferenceSpaceType() == OCIO::REFERENCE_SPACE_SCENE)
            xyz = cs->getName();
    }

    OCIO::ConstColorSpaceRcPtr space(const std::string& name) const {
        if (auto cs = name.empty() ? nullptr : config->getColorSpace(name.c_str())) return cs;
        throw ImageError("unknown colour space '" + name + "' in " + description);
    }

    // Converts packed RGB floats; both names must be canonical.
    void apply(float* rgb, size_t pixels, const std::string& from, const std::string& to) const {
        OCIO::ConstCPUProcessorRcPtr cpu;
        try {
            cpu = config->getProcessor(from.c_str(), to.c_str())->getDefaultCPUProcessor();
        } catch (const OCIO::Exception& e) {
            throw ImageError("cannot convert colour space '" + from + "' to '" + to + "': " + e.what());
        }
        // OCIO buffers a whole row, so one huge row would double the memory use.
        constexpr size_t kChunk = size_t{1} << 16;
        for (size_t begin = 0; begin < pixels; begin += kChunk) {
            OCIO::PackedImageDesc desc(rgb + 3 * begin, static_cast<long>(std::min(kChunk, pixels - begin)), 1, 3);
            cpu->apply(desc);
        }
    }
};

ColourConfig::ColourConfig() {
    if (const char* env = std::getenv("OCIO"); env && *env)
        impl_ = std::make_unique<Impl>(env, std::string(env) + " (from $OCIO)");
    else {
        const auto file = shipped_config();
        impl_ = std::make_unique<Impl>(file, file.string() + " (shipped with envmis)");
    }
}

ColourConfig::ColourConfig(const std::filesystem::path& config_file)
    : impl_(std::make_unique<Impl>(config_file, config_file.string())) {}

ColourConfig::~ColourConfig() = default;
ColourConfig::ColourConfig(ColourConfig&&) noexcept = default;
ColourConfig& ColourConfig::operator=(ColourConfig&&) noexcept = default;

std::string ColourConfig::description() const { return impl_->description; }

std::vector<std::string> ColourConfig::spaces() const {
    const auto& config = *impl_->config;
    const int n = config.getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL);
    std::vector<std::string> names;
    for (int i = 0; i < n; ++i)
        names.emplace_back(config.getColorSpaceNameByIndex(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL, i));
    return names;
}

bool ColourConfig::has_space(const std::string& name) const { return !resolve(name).empty(); }

std::string ColourConfig::resolve(const std::string& name) const {
    // OCIO matches names, aliases and roles case-insensitively.
    auto cs = name.empty() ? nullptr : impl_->config->getColorSpace(name.c_str());
    return cs ? cs->getName() : std::string();
}

LumaCoefficients ColourConfig::luma(const std::string& space) const {
    const auto cs = impl_->space(space);
    // The config's declared coefficients belong to its scene_linear space: for Rec.709
    // they are BT.709's own rounded weights (0.2126, 0.7152, 0.0722), which documents
    // and independent checks use, rather than the XYZ row they round (0.212639, ...).
    const auto scene_linear = impl_->config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
    const bool is_scene_linear = scene_linear && std::string(scene_linear->getName()) == cs->getName();
    if (impl_->xyz.empty() || cs->isData() || is_scene_linear) {
        double k[3];
        impl_->config->getDefaultLumaCoefs(k);
        return {static_cast<float>(k[0]), static_cast<float>(k[1]), static_cast<float>(k[2])};
    }
    float primaries[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    impl_->apply(primaries, 3, cs->getName(), impl_->xyz);
    return {primaries[1], primaries[4], primaries[7]};
}

void ColourConfig::convert(std::span<Rgb> pixels, const std::string& from, const std::string& to) const {
    const std::string source = impl_->space(from)->getName(), target = impl_->space(to)->getName();
    if (source != target) impl_->apply(reinterpret_cast<float*>(pixels.data()), pixels.size(), source, target);
}

}  // namespace envmis::io
