// The processor the library runs on, and the path each family of batch kernels takes
// on it: lookup_many and sample_many (envmap.h, binned.h) and the estimator's lanes
// (envmis::study). Chosen once per process by rules measured per CPU family
// (choose_batch_paths), or forced with the environment variable ENVMIS_SIMD=scalar or
// avx2 (tests, benchmarks). Every path gives bit-identical results; only speed differs.
//
// Cost: cpu_info() and batch_paths() run cpuid and read the environment once, on their
// first call; later calls return the same immutable value.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "envmis/core_export.h"

namespace envmis {

// How a batch kernel runs: one lane at a time, software-pipelined with prefetches
// (scalar), or eight lanes at a time in AVX2 with hardware gathers (avx2).
enum class BatchPath : uint8_t { scalar, avx2 };
ENVMIS_CORE_API std::string_view to_string(BatchPath p) noexcept;

// What cpuid says, and what of it the operating system lets a program use.
struct CpuInfo {
    std::string vendor;              // "GenuineIntel", "AuthenticAMD", ...; empty off x86-64
    std::string brand;               // the brand string, as the (virtual) machine reports it
    uint32_t family = 0, model = 0;  // display family and model (base plus extended fields)
    bool avx2 = false;               // AVX2 present and its registers saved by the OS
    bool avx512 = false;             // AVX-512 F, BW, DQ and VL likewise (no kernel uses it: see below)
};
ENVMIS_CORE_API const CpuInfo& cpu_info() noexcept;
// "<brand> (<vendor> family and model in hex, AVX2, AVX-512)": for benchmark output.
ENVMIS_CORE_API std::string cpu_name();

// How many threads this process can run at once: the CPUs its affinity mask allows
// (taskset, a batch system's binding), no more than its cgroup's CPU quota (a
// container's or a Slurm job's limit, rounded up) and no more than the environment
// variable ENVMIS_THREADS where that is a whole number from 1 to 65536 (the `--threads`
// of the envmis commands; a renderer may set it as it would OMP_NUM_THREADS, before it
// starts threads: getenv beside a setenv is a data race), at least 1.
// Read on each call (a process may be moved); the thread count of every parallel loop of
// the libraries (builds, bins, encodings) and the default of every envmis command.
ENVMIS_CORE_API uint32_t usable_cores() noexcept;
// The same from a cgroup's limit as written in cpu.max (v2: "QUOTA PERIOD" or "max
// PERIOD") or v1's cfs_quota_us and cfs_period_us joined by a space: quota / period
// rounded up, or 0 for no limit (or text it cannot read).
ENVMIS_CORE_API uint32_t cores_of_cpu_quota(std::string_view cpu_max) noexcept;

// The path of each kernel family; `forced` is ENVMIS_SIMD's value (empty when unset),
// `unavailable` true when it names a path this CPU or build lacks, which then runs
// scalar instead (a test of that path must skip, not pass).
struct BatchPaths {
    BatchPath lookup = BatchPath::scalar;  // lookup_many
    BatchPath sample = BatchPath::scalar;  // sample_many
    BatchPath lanes = BatchPath::scalar;   // the estimator's lanes
    std::string forced;
    bool unavailable = false;
};
// The rules (measured: docs/performance-log.md, 'choose_batch_paths'), equirect and
// equal-area maps alike:
// - lookup_many's AVX2 kernel wherever AVX2 is usable;
// - sample_many's AVX2 kernel on Intel and on AMD whose family is 0x19 or later: its gathers
//   pay; the scalar pipeline on older AMD families (not measured);
// - the estimator's lanes (arithmetic, no gathers of their own) wherever AVX2 is usable.
// No AVX-512 path: much of the kernels' time goes to gathers, and a 16-lane gather of
// eight 64-bit pairs was slower than the two 8-lane AVX2 gathers of the same pairs.
ENVMIS_CORE_API BatchPaths choose_batch_paths(const CpuInfo& cpu, std::string_view forced);
// choose_batch_paths(cpu_info(), ENVMIS_SIMD), once.
ENVMIS_CORE_API const BatchPaths& batch_paths() noexcept;
// "lookup_many=scalar sample_many=scalar lanes=avx2" (and the forcing, if any).
ENVMIS_CORE_API std::string batch_paths_summary();

}  // namespace envmis
