#pragma once
// Deterministic synthetic volumes, `synthetic:NAME[:N]` on the command line. All are N^3
// samples with spacing 1 and origin 0, centred at index c = (N - 1) / 2.
#include <string>
#include <vector>

#include "splat/volume.h"

namespace splat {

/// Names accepted by makeSynthetic.
std::vector<std::string> syntheticNames();

/// Default N for a name when none is given (phantom: 128, others: 64).
int syntheticDefaultSize(const std::string& name);

/// - `ct-phantom`: the same head in Hounsfield units (HU = 1000 (d - 1): air -1000, skull
///   +1000), background value -1000.
/// - `phantom`: 3D Shepp-Logan head phantom (Kak & Slaney ellipsoids), densities 0..2,
///   the head's long axis along z (upright).
/// - `blob`: one Gaussian, d(p) = exp(-|p - c|^2 / (2 s^2)) with s = N / 8.
/// - `cube`: value 1 for |p - c|_inf < N / 4, 0 elsewhere.
/// - `sphere`: a ball of radius R = 0.375 N with a smooth (antialiased) edge: d = S(t),
///   t = (R + w - |p - c|) / (2 w) clamped to [0, 1], S(t) = 6t^5 - 15t^4 + 10t^3, half-width
///   w = syntheticSphereEdge(): exactly 1 inside R - w, 0 beyond R + w, 1/2 at R. (A binary
///   ball's central-difference normals take 13 directions; shading could not follow the
///   cosine to 2%. Sum of d: 4/3 pi (R^3 + 3 R w^2 / 7).)
/// - `marschner-lobb`: the Marschner-Lobb test signal (fM = 6, alpha = 0.25) over
///   [-1, 1]^3, values in [0, 1].
/// Throws splat::Error for an unknown name or N outside [1, 2048].
Volume makeSynthetic(const std::string& name, int n);
/// The samples [lo, hi) of makeSynthetic(name, n) alone (a brick, splat/bricks.h), origin
/// lo: only they are computed and held.
Volume makeSyntheticBrick(const std::string& name, int n, const glm::ivec3& lo,
                          const glm::ivec3& hi);

/// Radius in voxels of the `sphere` volume, 0.375 N.
inline double syntheticSphereRadius(int n) { return 0.375 * n; }
/// Half-width in voxels of the `sphere` volume's edge.
inline double syntheticSphereEdge() { return 2.5; }
/// Standard deviation in voxels of the `blob` volume, N / 8.
inline double syntheticBlobSigma(int n) { return n / 8.0; }

}  // namespace splat
