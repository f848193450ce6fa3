#pragma once
// Closed forms of the default kernel's footprint and cumulative slab integral (the
// C1-tapered Gaussian of kernel.h, truncation via erf): the yardstick the footprint and
// slab tables are tested and benchmarked against.
#include "footprint/kernel.h"

namespace footprint {

/// fp(r) = integral h(sqrt(r^2 + z^2)) dz for a Gaussian kernel; 0 for r >= R.
double gaussianFootprintClosedForm(const Kernel& k, double r);

/// C(r, z) = integral_{-R}^{z} h(sqrt(r^2 + z'^2)) dz' for a Gaussian kernel (z clamped to
/// the kernel's extent along the line).
double gaussianCumulativeClosedForm(const Kernel& k, double r, double z);

}  // namespace footprint
