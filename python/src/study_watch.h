// Long study calls from Python: run with the GIL released, stoppable with Ctrl-C.
//
// The work runs on a thread of its own while the calling (Python) thread waits on it in
// slices of kPollInterval, the GIL released during each. Between slices it holds the
// GIL, so it can run Python's signal handlers (PyErr_CheckSignals: SIGINT raises
// KeyboardInterrupt) and call the caller's progress callback. When either raises, it sets
// the run's stop flag (RunControl::stop, which the study checks between points and every
// few thousand estimates), waits for the work to return and re-raises the Python error:
// partial results are dropped.
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <future>
#include <utility>

#include "envmis/study/comparison/comparison.h"

namespace envmis::python {

namespace py = pybind11;

inline constexpr std::chrono::milliseconds kPollInterval{50};

// What a watched run shares with its worker: the stop flag and the latest progress.
struct Watch {
    std::atomic<bool> stop{false};
    std::atomic<size_t> done{0}, total{0};
    py::object progress;  // None, or a callable (done, total) called on the Python thread

    RunControl control() {
        return {&stop, [this](size_t d, size_t t) {
                    total.store(t);
                    done.store(d);
                }};
    }
};

// Runs `work()` (which must honour watch.stop where it can) and returns its result or
// rethrows its exception; raises the Python error of a signal handler or of the
// progress callback once the work has stopped. The callback sees each poll's latest
// progress and the final one. Call with the GIL held.
template <class Work>
auto run_watched(Work&& work, Watch& watch) -> decltype(work()) {
    auto future = std::async(std::launch::async, std::forward<Work>(work));
    size_t reported = static_cast<size_t>(-1);
    auto report = [&] {
        const size_t done = watch.done.load();
        if (!watch.progress.is_none() && done != reported && watch.total.load() > 0) {
            reported = done;
            watch.progress(done, watch.total.load());
        }
    };
    for (;;) {
        bool ready = false;
        {
            py::gil_scoped_release release;
            ready = future.wait_for(kPollInterval) == std::future_status::ready;
        }
        if (ready) {
            auto result = future.get();
            report();  // the end, which a short run reaches before any poll
            return result;
        }
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            report();
        } catch (...) {
            watch.stop = true;
            {
                py::gil_scoped_release release;
                future.wait();
            }
            throw;
        }
    }
}

}  // namespace envmis::python
