// cpuid, xgetbv and the rules of envmis/cpu.h; the usable cores (affinity, cgroup quota).
#include "envmis/cpu.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#if defined(__linux__)
#include <sched.h>
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <cpuid.h>
#define ENVMIS_HAS_CPUID 1
#endif

namespace envmis {
namespace {

#ifdef ENVMIS_HAS_CPUID
struct Regs {
    unsigned a = 0, b = 0, c = 0, d = 0;
};
Regs cpuid(unsigned leaf, unsigned sub = 0) noexcept {
    Regs r;
    __cpuid_count(leaf, sub, r.a, r.b, r.c, r.d);
    return r;
}

// XCR0: which register states the OS saves on a context switch.
uint64_t xcr0() noexcept {
    unsigned lo = 0, hi = 0;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    return (uint64_t{hi} << 32) | lo;
}

std::string trimmed(const char* s) {
    std::string t(s);
    const size_t first = t.find_first_not_of(' '), last = t.find_last_not_of(' ');
    return first == std::string::npos ? std::string() : t.substr(first, last - first + 1);
}

CpuInfo read_cpu() {
    CpuInfo cpu;
    const Regs id = cpuid(0);
    char vendor[13] = {};
    std::memcpy(vendor, &id.b, 4), std::memcpy(vendor + 4, &id.d, 4), std::memcpy(vendor + 8, &id.c, 4);
    cpu.vendor = vendor;
    const Regs f1 = cpuid(1);
    const unsigned base_family = (f1.a >> 8) & 0xf, base_model = (f1.a >> 4) & 0xf;
    cpu.family = base_family == 0xf ? base_family + ((f1.a >> 20) & 0xff) : base_family;
    cpu.model = base_family == 0x6 || base_family == 0xf ? (((f1.a >> 16) & 0xf) << 4) | base_model : base_model;
    const bool osxsave = (f1.c >> 27) & 1, avx = (f1.c >> 28) & 1;
    const uint64_t xcr = osxsave ? xcr0() : 0;
    const bool ymm = (xcr & 0x6) == 0x6, zmm = (xcr & 0xe6) == 0xe6;
    if (id.a >= 7) {
        const Regs f7 = cpuid(7);
        cpu.avx2 = avx && ymm && ((f7.b >> 5) & 1);
        const bool f = (f7.b >> 16) & 1, dq = (f7.b >> 17) & 1, bw = (f7.b >> 30) & 1, vl = (f7.b >> 31) & 1;
        cpu.avx512 = cpu.avx2 && zmm && f && dq && bw && vl;
    }
    if (cpuid(0x80000000).a >= 0x80000004) {
        char brand[49] = {};
        for (unsigned i = 0; i < 3; ++i) {
            const Regs r = cpuid(0x80000002 + i);
            std::memcpy(brand + 16 * i, &r, 16);
        }
        cpu.brand = trimmed(brand);
    }
    return cpu;
}
#else
CpuInfo read_cpu() { return {}; }
#endif

}  // namespace

std::string_view to_string(BatchPath p) noexcept { return p == BatchPath::avx2 ? "avx2" : "scalar"; }

const CpuInfo& cpu_info() noexcept {
    static const CpuInfo cpu = read_cpu();
    return cpu;
}

std::string cpu_name() {
    const CpuInfo& cpu = cpu_info();
    if (cpu.vendor.empty()) return "unknown (not x86-64)";
    char ids[64];
    std::snprintf(ids, sizeof ids, "family 0x%x model 0x%x", cpu.family, cpu.model);
    std::string name = (cpu.brand.empty() ? std::string("unnamed") : cpu.brand) + " (" + cpu.vendor + " " + ids;
    if (cpu.avx2) name += ", AVX2";
    if (cpu.avx512) name += ", AVX-512";
    return name + ")";
}

BatchPaths choose_batch_paths(const CpuInfo& cpu, std::string_view forced) {
    BatchPaths paths;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    constexpr bool built = true;  // detail/simd.h's ENVMIS_AVX2_BATCHES
#else
    constexpr bool built = false;
#endif
    const bool avx2 = built && cpu.avx2;
    paths.forced = forced;
    if (forced == "scalar") return paths;
    if (forced == "avx2") {
        paths.unavailable = !avx2;
        if (avx2) paths.lookup = paths.sample = paths.lanes = BatchPath::avx2;
        return paths;
    }
    if (!forced.empty()) {  // a name no path of this build answers to (avx512)
        paths.unavailable = true;
        return paths;
    }
    // The AVX2 sampler where its gathers pay: Intel, and AMD whose family is 0x19 or later (there
    // they are microcoded, but the sampler's time goes to memory); older AMD families are
    // not measured, and the scalar pipeline is the safe choice there (cpu.h; measured:
    // docs/performance-log.md, 'choose_batch_paths').
    const bool gathers_pay = cpu.vendor == "GenuineIntel" || (cpu.vendor == "AuthenticAMD" && cpu.family >= 0x19);
    paths.lanes = paths.lookup = avx2 ? BatchPath::avx2 : BatchPath::scalar;
    paths.sample = avx2 && gathers_pay ? BatchPath::avx2 : BatchPath::scalar;
    return paths;
}

const BatchPaths& batch_paths() noexcept {
    static const BatchPaths paths = [] {
        const char* forced = std::getenv("ENVMIS_SIMD");
        return choose_batch_paths(cpu_info(), forced ? forced : "");
    }();
    return paths;
}

std::string batch_paths_summary() {
    const BatchPaths& p = batch_paths();
    std::string s = "lookup_many=" + std::string(to_string(p.lookup)) +
                    " sample_many=" + std::string(to_string(p.sample)) + " lanes=" + std::string(to_string(p.lanes));
    if (!p.forced.empty()) s += " (ENVMIS_SIMD=" + p.forced + (p.unavailable ? ": unavailable, scalar)" : ")");
    return s;
}

uint32_t cores_of_cpu_quota(std::string_view cpu_max) noexcept {
    const std::string text(cpu_max);
    double quota = 0, period = 0;
    if (std::sscanf(text.c_str(), "%lf %lf", &quota, &period) != 2 || !(quota > 0) || !(period > 0)) return 0;
    const double cores = std::ceil(quota / period);
    return cores < 1 ? 1 : cores > 65536 ? 65536 : static_cast<uint32_t>(cores);
}

namespace {
// The first line of a small file, or "" where it cannot be read.
std::string first_line(const char* path) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);
    return line;
}
}  // namespace

uint32_t usable_cores() noexcept {
    uint32_t cores = std::max(1u, std::thread::hardware_concurrency());
#if defined(__linux__)
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        cores = static_cast<uint32_t>(CPU_COUNT(&set));
    try {
        uint32_t quota = cores_of_cpu_quota(first_line("/sys/fs/cgroup/cpu.max"));
        if (quota == 0)
            quota = cores_of_cpu_quota(first_line("/sys/fs/cgroup/cpu/cpu.cfs_quota_us") + " " +
                                       first_line("/sys/fs/cgroup/cpu/cpu.cfs_period_us"));
        if (quota > 0) cores = std::min(cores, quota);
    } catch (...) {  // allocation failure reading the files: the affinity's count stands
    }
#endif
    if (const char* limit = std::getenv("ENVMIS_THREADS")) {
        char* end = nullptr;
        const unsigned long n = std::isdigit(static_cast<unsigned char>(*limit)) ? std::strtoul(limit, &end, 10) : 0;
        if (end && *end == '\0' && n >= 1 && n <= 65536) cores = std::min(cores, static_cast<uint32_t>(n));
    }
    return cores;
}

}  // namespace envmis
