// envmis::core in one include, for people who do not care which stage a name lives in.
// The runtime a renderer links: no third-party dependency. Its headers follow the data
// path, each stage using only those before it:
//   math/          vectors, fast polynomial maths, random numbers, hashing
//   image/         RGB images and bad-pixel repair, mappings and axes
//   compensation/  the compensation threshold (Karlik et al. 2019)
//   sampling/      2D distributions (cdf.h: the plain algorithm; distribution.h: its
//                  tuning) and the environment-map sampler, with batch calls;
//                  binned.h: normal-aware bins (a density per bin of shading normals)
//   table/         table files: their layout, read or memory-mapped
// interrupt.h, used by every stage, lets a caller stop the long builds; large_vector.h
// holds the large buffers (pixels, tables) on huge pages.
#pragma once

#include "envmis/compensation/compensation.h"
#include "envmis/image/image.h"
#include "envmis/image/mapping.h"
#include "envmis/interrupt.h"
#include "envmis/large_vector.h"
#include "envmis/math/fast_math.h"
#include "envmis/math/hash.h"
#include "envmis/math/math.h"
#include "envmis/math/random.h"
#include "envmis/sampling/binned.h"
#include "envmis/sampling/cdf.h"
#include "envmis/sampling/distribution.h"
#include "envmis/sampling/envmap.h"
#include "envmis/table/format.h"
#include "envmis/table/table.h"
