#include "envmis/cpu.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <thread>
#if defined(__linux__)
#include <sched.h>
#endif

#include "forced_path.h"

namespace envmis {
namespace {

CpuInfo cpu(const char* vendor, uint32_t family, bool avx2) {
    CpuInfo c;
    c.vendor = vendor, c.family = family, c.avx2 = avx2;
    return c;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
TEST(Cpu, EachKernelTakesThePathMeasuredFasterOnItsCpuFamily) {
    const BatchPaths intel = choose_batch_paths(cpu("GenuineIntel", 6, true), "");
    EXPECT_EQ(intel.lookup, BatchPath::avx2);
    EXPECT_EQ(intel.sample, BatchPath::avx2);
    EXPECT_EQ(intel.lanes, BatchPath::avx2);
    for (const uint32_t family : {0x17u, 0x19u, 0x1au}) {
        const BatchPaths amd = choose_batch_paths(cpu("AuthenticAMD", family, true), "");
        EXPECT_EQ(amd.lookup, BatchPath::avx2) << family;
        EXPECT_EQ(amd.sample, family >= 0x19 ? BatchPath::avx2 : BatchPath::scalar) << family;
        EXPECT_EQ(amd.lanes, BatchPath::avx2) << family;
        EXPECT_FALSE(amd.unavailable);
    }
}

TEST(Cpu, AForcedPathRunsEverywhereTheCpuHasIt) {
    const BatchPaths avx2 = choose_batch_paths(cpu("AuthenticAMD", 0x1a, true), "avx2");
    EXPECT_EQ(avx2.lookup, BatchPath::avx2);
    EXPECT_EQ(avx2.sample, BatchPath::avx2);
    EXPECT_FALSE(avx2.unavailable);
    const BatchPaths scalar = choose_batch_paths(cpu("GenuineIntel", 6, true), "scalar");
    EXPECT_EQ(scalar.lookup, BatchPath::scalar);
    EXPECT_EQ(scalar.sample, BatchPath::scalar);
    EXPECT_EQ(scalar.lanes, BatchPath::scalar);
    EXPECT_FALSE(scalar.unavailable);
}
#endif

TEST(Cpu, AForcedPathTheCpuLacksRunsScalarAndSaysSo) {
    for (const char* forced : {"avx2", "avx512", "fast"}) {
        const BatchPaths p = choose_batch_paths(cpu("GenuineIntel", 6, false), forced);
        EXPECT_TRUE(p.unavailable) << forced;
        EXPECT_EQ(p.lookup, BatchPath::scalar) << forced;
        EXPECT_EQ(p.sample, BatchPath::scalar) << forced;
        EXPECT_EQ(p.lanes, BatchPath::scalar) << forced;
        EXPECT_EQ(p.forced, forced);
    }
    const BatchPaths without = choose_batch_paths(cpu("GenuineIntel", 6, false), "");
    EXPECT_FALSE(without.unavailable);
    EXPECT_EQ(without.lookup, BatchPath::scalar);
    EXPECT_EQ(without.lanes, BatchPath::scalar);
}

// The paths.* tests run this with ENVMIS_SIMD set: the process takes the forced path.
TEST(Cpu, TheProcessTakesTheRulesPathsOrTheForcedOne) {
    ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE();
    const char* forced = std::getenv("ENVMIS_SIMD");
    const BatchPaths& p = batch_paths();
    if (!forced || !*forced) {
        const BatchPaths rules = choose_batch_paths(cpu_info(), "");
        EXPECT_TRUE(p.lookup == rules.lookup && p.sample == rules.sample && p.lanes == rules.lanes);
        EXPECT_TRUE(p.forced.empty());
        return;
    }
    EXPECT_EQ(p.forced, forced);
    for (const BatchPath path : {p.lookup, p.sample, p.lanes}) EXPECT_EQ(to_string(path), forced);
}

TEST(Cpu, NamesTheCpuAndThePaths) {
    EXPECT_FALSE(cpu_name().empty());
    EXPECT_NE(batch_paths_summary().find("lookup_many="), std::string::npos);
#if defined(__x86_64__)
    EXPECT_FALSE(cpu_info().vendor.empty());
    EXPECT_GT(cpu_info().family, 0u);
#endif
}

TEST(Cpu, ACgroupQuotaGivesItsCoresRoundedUpAndNoLimitGivesNone) {
    EXPECT_EQ(cores_of_cpu_quota("200000 100000"), 2u);  // cgroup v2 cpu.max
    EXPECT_EQ(cores_of_cpu_quota("150000 100000"), 2u);
    EXPECT_EQ(cores_of_cpu_quota("50000 100000"), 1u);
    EXPECT_EQ(cores_of_cpu_quota("max 100000"), 0u);
    EXPECT_EQ(cores_of_cpu_quota("-1 100000"), 0u);  // cgroup v1 without a limit
    EXPECT_EQ(cores_of_cpu_quota(""), 0u);
    EXPECT_EQ(cores_of_cpu_quota(" 100000"), 0u);
    EXPECT_EQ(cores_of_cpu_quota("100000 0"), 0u);
    EXPECT_EQ(cores_of_cpu_quota("1e30 1"), 65536u);
}

#if defined(__linux__)
// A thread bound to one CPU (as `taskset -c 0` binds a process) may use one core.
TEST(Cpu, UsableCoresFollowTheAffinityMask) {
    cpu_set_t all;
    ASSERT_EQ(sched_getaffinity(0, sizeof all, &all), 0);
    EXPECT_LE(usable_cores(), static_cast<uint32_t>(CPU_COUNT(&all)));
    EXPECT_GE(usable_cores(), 1u);
    uint32_t bound = 0;
    std::thread([&] {
        cpu_set_t one;
        CPU_ZERO(&one);
        for (int c = 0; c < CPU_SETSIZE; ++c)
            if (CPU_ISSET(c, &all)) {
                CPU_SET(c, &one);
                break;
            }
        if (sched_setaffinity(0, sizeof one, &one) == 0) bound = usable_cores();
    }).join();
    EXPECT_EQ(bound, 1u);
}
#endif

// ENVMIS_THREADS (the commands' --threads) caps the count where it is a whole number from 1
// to 65536; anything else is ignored.
TEST(Cpu, UsableCoresStayWithinEnvmisThreads) {
    const char* inherited = std::getenv("ENVMIS_THREADS");
    const std::string kept = inherited ? inherited : "";
    ::unsetenv("ENVMIS_THREADS");
    const uint32_t cores = usable_cores();
    const auto with = [](const char* value) {
        ::setenv("ENVMIS_THREADS", value, 1);
        const uint32_t n = usable_cores();
        ::unsetenv("ENVMIS_THREADS");
        return n;
    };
    EXPECT_EQ(with("1"), 1u);
    EXPECT_EQ(with("65536"), cores);
    for (const char* ignored : {"0", "", "abc", "2x", "-1", " 1", "65537", "99999999999999999999"})
        EXPECT_EQ(with(ignored), cores) << "'" << ignored << "'";
    if (inherited) ::setenv("ENVMIS_THREADS", kept.c_str(), 1);
}

}  // namespace
}  // namespace envmis
