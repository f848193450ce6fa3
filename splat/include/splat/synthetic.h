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

/// - `phantom`: 3D Shepp-Logan head phantom (Kak & Slaney ellipsoids), densities 0..2,
///   the head's long axis along z (upright).
/// - `blob`: one Gaussian, d(p) = exp(-|p - c|^2 / (2 s^2)) with s = N / 8.
/// - `cube`: value 1 for |p - c|_inf < N / 4, 0 elsewhere.
/// - `sphere`: value 1 for |p - c| < 0.375 N, 0 elsewhere (binary ball).
/// - `marschner-lobb`: the Marschner-Lobb test signal (fM = 6, alpha = 0.25) over
///   [-1, 1]^3, values in [0, 1].
/// Throws splat::Error for an unknown name or N outside [1, 2048].
Volume makeSynthetic(const std::string& name, int n);

/// Radius in voxels of the `sphere` volume, 0.375 N.
inline double syntheticSphereRadius(int n) { return 0.375 * n; }
/// Standard deviation in voxels of the `blob` volume, N / 8.
inline double syntheticBlobSigma(int n) { return n / 8.0; }

}  // namespace splat
