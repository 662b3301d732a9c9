// The batch tests run once more with each path forced by ENVMIS_SIMD (tests/CMakeLists.txt,
// tests paths.*): where the CPU or build lacks the forced path, the kernels run scalar,
// and a test that passed then would claim a path it never ran, so it skips, naming why.
#pragma once

#include <gtest/gtest.h>

#include "envmis/cpu.h"

#define ENVMIS_SKIP_IF_FORCED_PATH_UNAVAILABLE()                                                   \
    if (::envmis::batch_paths().unavailable)                                                       \
    GTEST_SKIP() << "ENVMIS_SIMD=" << ::envmis::batch_paths().forced << " names a path this CPU (" \
                 << ::envmis::cpu_name() << ") or build lacks; the kernels ran scalar"
