#pragma once
// The kept region of a Clipping (splat/settings.h) as every renderer needs it: which voxels a
// scene must keep so that the reconstruction is complete up to the cut, and the interval of
// a ray inside the region (the reference clips its ray to it; the splatters cut their sheets
// at it, frame/clip_cut.h). The field itself is never changed: the cut face shows the
// reconstruction of all the data at the cut, not a kernel-blurred edge of dropped voxels.
#include <glm/glm.hpp>

#include "splat/settings.h"

namespace splat {

/// False when no point within `margin` (per world axis) of x is kept: the voxel at x cannot
/// contribute to the field inside the region (its kernel reaches `margin` at most).
bool keepsNear(const Clipping& c, const glm::dvec3& x, const glm::dvec3& margin);

/// True when the kept region contains the whole box [lo, hi]: clipping changes nothing.
bool containsBox(const Clipping& c, const glm::dvec3& lo, const glm::dvec3& hi);

/// Narrows [t0, t1] to the part of the ray origin + t dir inside the kept region; false (and
/// t0 > t1) when the ray misses it. Infinite ends stay infinite.
bool keptInterval(const Clipping& c, const glm::dvec3& origin, const glm::dvec3& dir, double& t0,
                  double& t1);

}  // namespace splat
