// Stopping a long build from outside it: a flag that another thread, a user interface or
// a signal handler sets (a lock-free std::atomic<bool> is async-signal-safe to store to).
//
// The builds that can run for seconds take an optional StopFlag as their last argument
// (EnvMap, BinnedEnvMap, remap, write_table); null, the default, means never stop. They
// read it with a relaxed load every block of rows or bins (at most a few milliseconds of
// work apart on one core) and, once it is set, discard what they built and throw
// Interrupted: nothing half-built is returned, and write_table leaves no file behind.
// The sampling calls never check it: they stay noexcept and allocation-free.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>

#include "envmis/core_export.h"

namespace envmis {

// A flag to watch, or null. The flag must outlive the call that watches it.
using StopFlag = const std::atomic<bool>*;

// What a build throws when its StopFlag was set. what() is "interrupted" unless the
// thrower says what the interruption left (e.g. which results are partial).
class ENVMIS_CORE_API Interrupted : public std::runtime_error {
public:
    Interrupted() : std::runtime_error("interrupted") {}
    explicit Interrupted(const std::string& what) : std::runtime_error(what) {}
};

inline bool stop_requested(StopFlag stop) noexcept { return stop && stop->load(std::memory_order_relaxed); }

inline void throw_if_stopped(StopFlag stop) {
    if (stop_requested(stop)) throw Interrupted();
}

}  // namespace envmis
