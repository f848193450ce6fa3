// The reference ray caster's fields (see field.h).
#include "reference/field.h"

namespace splat {

ReferenceField::ReferenceField(const Volume& volume, const SplatList& splats,
                               const footprint::Kernel& kernel, bool preClassifiedDvr)
    : lut_(kernel), radius_(kernel.radius()), four_(preClassifiedDvr) {
    if (four_)
        grid4_ = buildGrid<4>(volume, splats, lut_, radius_,
                              {&splats.extinction, &splats.r, &splats.g, &splats.b});
    else
        grid1_ = buildGrid<1>(volume, splats, lut_, radius_, {&splats.density});
}

}  // namespace splat
