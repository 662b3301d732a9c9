// Specification of the stop flag of the core's long builds (interrupt.h): set, each
// build throws Interrupted and returns or writes nothing; clear, it changes nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>

#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/build/remap.h"
#include "envmis/build/table_writer.h"
#include "envmis/interrupt.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/envmap.h"
#include "envmis/table/table.h"
#include "maps.h"

namespace envmis {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kSeed = 7;

TEST(StopFlag, ASetFlagStopsAnEnvMapBuild) {
    const std::atomic<bool> stop{true};
    EXPECT_THROW(build_env_map(test::random_map(64, 32, kSeed), {}, &stop), Interrupted);
}

TEST(StopFlag, AClearFlagBuildsTheSameMapAsNone) {
    const std::atomic<bool> stop{false};
    const EnvMap watched = build_env_map(test::random_map(64, 32, kSeed), {}, &stop),
                 plain = build_env_map(test::random_map(64, 32, kSeed));
    EXPECT_EQ(watched.density(), plain.density());
    EXPECT_EQ(watched.stats().mean_luminance, plain.stats().mean_luminance);
}

TEST(StopFlag, ASetFlagStopsABinnedBuild) {
    EnvMapOptions options;
    options.compensation.enabled = false;
    const EnvMap plain = build_env_map(test::random_map(64, 32, kSeed), options);
    const std::atomic<bool> stop{true};
    EXPECT_THROW(build_bins(EnvMap(plain), BinnedOptions{}, &stop), Interrupted);
}

TEST(StopFlag, ASetFlagStopsARemap) {
    const std::atomic<bool> stop{true};
    EXPECT_THROW(remap(test::random_map(64, 32, kSeed), Mapping::equirect, Mapping::equal_area, 32, 32, 0, &stop),
                 Interrupted);
}

TEST(StopFlag, ASetFlagStopsATableWriteAndLeavesNoFile) {
    const fs::path folder = fs::temp_directory_path() / ("envmis_stop_test_" + std::to_string(::getpid()));
    fs::remove_all(folder);
    fs::create_directories(folder);
    const EnvMap map = build_env_map(test::random_map(64, 32, kSeed));
    const std::atomic<bool> stop{true};
    EXPECT_THROW(write_table(folder / "map.envmis", map, {}, TableEncoding::full, &stop), Interrupted);
    EXPECT_TRUE(fs::is_empty(folder));
    fs::remove_all(folder);
}

}  // namespace
}  // namespace envmis
