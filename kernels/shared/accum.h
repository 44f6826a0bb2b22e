/* accum.h: compensated (Kahan) accumulation of per-pass partial sums, so 10⁵–10⁶ samples per pixel
 * lose no precision in float storage (DESIGN.md, pathtrace). Needs IEEE evaluation order: no
 * -cl-fast-relaxed-math, which may reassociate the compensation away. */
#ifndef NARVAL_ACCUM_H
#define NARVAL_ACCUM_H

#include "shared/compat.h"

static inline void accum_kahan_add(NV_PRIVATE float* sum, NV_PRIVATE float* comp, float x) {
  const float y = x - *comp;
  const float t = *sum + y;
  *comp = (t - *sum) - y;
  *sum = t;
}

#endif
