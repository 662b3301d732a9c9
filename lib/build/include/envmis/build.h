// envmis::build in one include: what makes tables, beside the runtime (envmis::core)
// that reads them. No third-party dependency.
//   build/env_map.h       an environment map from a radiance image
//   build/bins.h          the normal-aware map's bins, each bin's alpha chosen by exact variance
//   build/remap.h         resampling a map to another mapping or size, power kept
//   build/table_writer.h  writing table files (full or compact)
//   build/atomic_file.h   files written to a temporary and renamed when complete
#pragma once

#include "envmis/build/atomic_file.h"
#include "envmis/build/bins.h"
#include "envmis/build/env_map.h"
#include "envmis/build/remap.h"
#include "envmis/build/table_writer.h"
