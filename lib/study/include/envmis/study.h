// envmis::study in one include: the variance study of direct-lighting estimators built on
// envmis::core. Its headers follow the study's path from a shading point to a report:
//   study/shading/     the shading frame and the analytic BSDFs
//   study/techniques/  estimators: one or several samples per technique, SIMD lanes
//   study/weights/     MIS weights: balance, power, optimal (solve) and variance-aware
//   study/statistics/  running means and variances in doubles
//   study/reference/   exact references: quadrature over the map, the textbook sampler
//   study/comparison/  comparisons over shading points, their set-up, alpha choice and sweeps
#pragma once

#include "envmis/core.h"
#include "envmis/study/comparison/alpha.h"
#include "envmis/study/comparison/comparison.h"
#include "envmis/study/comparison/setup.h"
#include "envmis/study/comparison/sweeps.h"
#include "envmis/study/reference/quadrature.h"
#include "envmis/study/reference/textbook.h"
#include "envmis/study/shading/bsdf.h"
#include "envmis/study/shading/frame.h"
#include "envmis/study/statistics/statistics.h"
#include "envmis/study/techniques/estimator.h"
#include "envmis/study/weights/mis_weights.h"
