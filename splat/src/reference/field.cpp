// The reference ray caster's fields (see field.h).
#include "reference/field.h"

namespace splat {

ReferenceField::ReferenceField(const Volume& volume, const SplatList& splats,
                               const footprint::Kernel& kernel, FieldLayout layout,
                               ReferenceAcceleration acceleration)
    : lut_(kernel),
      acceleration_(acceleration),
      radius_(kernel.radius()),
      kernelDeviation_(std::sqrt(kernel.variance())),
      layout_(layout),
      background_(splats.background) {
    if (acceleration.separableKernel && kernel.type() == footprint::KernelType::Gaussian)
        gauss_ = std::make_unique<SeparableGaussian>(kernel);
    if (layout == FieldLayout::Emission) {
        grid4_ = buildGrid<4>(volume, splats, lut_, radius_,
                              {&splats.extinction, &splats.r, &splats.g, &splats.b},
                              splats.label.empty() ? nullptr : &splats.label);
        double bound = 0;
        for (std::size_t q = 0; q < splats.size() && std::isfinite(bound); ++q) {
            const double e = std::max({splats.r[q], splats.g[q], splats.b[q]});
            if (e <= 0) continue;
            const double rho = splats.extinction[q];
            bound = rho > 0 ? std::max(bound, e / rho) : std::numeric_limits<double>::infinity();
        }
        emissionRatioBound_ = bound;
    } else {
        // A paletted list holds densities by value: only they are expanded, for the build
        // (4 bytes a splat, freed after it), not the emission the layout does not read.
        std::vector<float> expanded;
        if (splats.density.empty() && splats.paletted()) {
            expanded.resize(splats.size());
            for (std::size_t q = 0; q < expanded.size(); ++q) expanded[q] = splats.densityOf(q);
        }
        const std::vector<float>* density = expanded.empty() ? &splats.density : &expanded;
        if (layout == FieldLayout::DensityGradient)
            grid4_ = buildGrid<4>(volume, splats, lut_, radius_,
                                  {density, &splats.gx, &splats.gy, &splats.gz});
        else
            grid1_ = buildGrid<1>(volume, splats, lut_, radius_, {density});
    }
    grid4_.gauss = grid1_.gauss = gauss_.get();
    if (gauss_) {
        if (layout == FieldLayout::Density)
            grid1_.buildWindowFlags(gauss_->window());
        else
            grid4_.buildWindowFlags(gauss_->window());
    }
}

}  // namespace splat
