// The reference ray caster's fields (see field.h).
#include "reference/field.h"

namespace splat {

ReferenceField::ReferenceField(const Volume& volume, const SplatList& splats,
                               const footprint::Kernel& kernel, FieldLayout layout)
    : lut_(kernel), radius_(kernel.radius()), layout_(layout), background_(splats.background) {
    if (layout == FieldLayout::Emission)
        grid4_ = buildGrid<4>(volume, splats, lut_, radius_,
                              {&splats.extinction, &splats.r, &splats.g, &splats.b},
                              splats.label.empty() ? nullptr : &splats.label);
    else if (layout == FieldLayout::DensityGradient)
        grid4_ = buildGrid<4>(volume, splats, lut_, radius_,
                              {&splats.density, &splats.gx, &splats.gy, &splats.gz});
    else
        grid1_ = buildGrid<1>(volume, splats, lut_, radius_, {&splats.density});
}

}  // namespace splat
