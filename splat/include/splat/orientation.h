#pragma once
// Orientation of arrays that arrive with an index-to-world affine (NIfTI sform/qform, NRRD
// space directions, nibabel's `img.affine`): x = t + M p for the index position p. splat's
// volume has its world axes along the index axes with positive spacing (splat/volume.h), so
// the signed axis permutation closest to M is applied to the samples, exactly as the file
// loaders do (the Python module's splat.from_nibabel uses it, so that an array and its
// affine give the volume splat.load gives for the file).
#include <glm/glm.hpp>
#include <string>

#include "splat/volume.h"

namespace splat {

/// Reorders and flips the samples of the owned float volume `v` (v.data, dims in file index
/// order) so that world axis w runs along index axis w in the positive direction; sets
/// spacing (the column norms of M) and origin (the world position of the new first sample).
/// A residual rotation larger than ~1e-3 is described in v.note (never dropped silently).
/// `what` names the matrix in errors and notes ("affine"). Throws splat::Error for a zero
/// or non-finite column of M.
void orientVolume(Volume& v, const glm::dmat3& M, const glm::dvec3& t, const std::string& what);

/// True when M is diagonal with positive entries: orientVolume only sets spacing and origin
/// (no sample moves).
bool isAxisAligned(const glm::dmat3& M);

}  // namespace splat
