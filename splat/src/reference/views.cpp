// Slices, MPR and CPR through the reference's field evaluator (splat/views.h).
#include "splat/views.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "footprint/kernel.h"
#include "model/scene_impl.h"
#include "reference/field.h"
#include "reference/reference_frame.h"
#include "splat/classify.h"
#include "splat/error.h"

namespace splat {

struct FieldView::Impl {
    const Volume& volume;
    footprint::Kernel kernel;
    SplatList splats;
    std::unique_ptr<ReferenceField> field;
    int threads;
    Impl(const Volume& v, const footprint::Kernel& k, int t) : volume(v), kernel(k), threads(t) {}
};

namespace {
footprint::Kernel viewKernel(const std::string& name, double sigma, double radius) {
    try {
        return footprint::Kernel::fromName(name, sigma, radius);
    } catch (const std::invalid_argument& e) {
        throw Error(e.what());
    }
}

/// Runs body(y) for every row in parallel on the view's threads.
template <class F>
void forRows(const FieldView& field, int height, F&& body) {
    runOnThreads(field.threads(), [&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, height),
                          [&](const tbb::blocked_range<int>& r) {
                              for (int y = r.begin(); y != r.end(); ++y) body(y);
                          });
    });
}
}  // namespace

FieldView::FieldView(const Volume& volume, const std::string& kernel, double sigma, double radius,
                     int threads) {
    if (!volume.hasSamples())
        throw Error("volume is empty or its sample count does not match its dimensions");
    impl_ = std::make_unique<Impl>(volume, viewKernel(kernel, sigma, radius), threads);
    validateReferenceKernel(impl_->kernel);
    runOnThreads(threads, [&] {
        // Every voxel with d != b (the transfer-function-free classification of xray/mip).
        impl_->splats = classify(volume, TransferFunction::preset("gray-ramp").resolved(0, 1),
                                 RenderMode::Xray, Classification::Pre, impl_->kernel.radius());
        impl_->field = std::make_unique<ReferenceField>(volume, impl_->splats, impl_->kernel,
                                                        FieldLayout::Density);
    });
}

FieldView::~FieldView() = default;

double FieldView::operator()(const glm::dvec3& world) const {
    return impl_->field->density(impl_->volume, world);
}
const Volume& FieldView::volume() const { return impl_->volume; }
double FieldView::partitionOfUnityRipple() const { return impl_->kernel.partitionOfUnityRipple(); }
double FieldView::kernelRadius() const { return impl_->kernel.radius(); }
int FieldView::threads() const { return impl_->threads; }

Image multiplanarReconstruction(const FieldView& field, const PlaneView& p) {
    if (p.width < 1 || p.height < 1 || p.width > 32768 || p.height > 32768)
        throw Error("view size must be between 1 and 32768 pixels per side");
    if (!(p.pixelSize > 0) || !std::isfinite(p.pixelSize))
        throw Error("view pixel size must be a positive number of world units");
    const double nl = glm::length(p.normal);
    if (!(nl > 0)) throw Error("the plane's normal must not be zero");
    const glm::dvec3 n = p.normal / nl;
    glm::dvec3 right = glm::cross(p.up, n);
    if (glm::length(right) < 1e-9 * std::max(1.0, glm::length(p.up)))
        throw Error("the plane's up vector must not be parallel to its normal");
    right = glm::normalize(right);
    const glm::dvec3 up = glm::cross(n, right);
    Image image(p.width, p.height);
    forRows(field, p.height, [&](int y) {
        for (int x = 0; x < p.width; ++x) {
            const glm::dvec3 w = p.point + (x + 0.5 - 0.5 * p.width) * p.pixelSize * right +
                                 (0.5 * p.height - y - 0.5) * p.pixelSize * up;
            image.at(x, y) = glm::vec4(glm::vec3(float(field(w))), 1.0f);
        }
    });
    return image;
}

PlaneView slicePlane(const Volume& v, int axis, int index) {
    if (axis < 0 || axis > 2) throw Error("slice axis must be x, y or z");
    if (index < 0 || index >= v.dims[axis])
        throw Error("slice " + std::to_string(index) + " is outside 0.." +
                    std::to_string(v.dims[axis] - 1));
    PlaneView p;
    const int a = axis == 0 ? 1 : 0;  // image right
    const int b = axis == 2 ? 1 : 2;  // image up
    p.normal = glm::dvec3(0.0);
    p.up = glm::dvec3(0.0);
    p.up[b] = 1.0;
    // normal such that up x normal = +right axis
    glm::dvec3 r(0.0);
    r[a] = 1.0;
    p.normal = glm::cross(r, p.up);
    p.pixelSize = v.minSpacing();
    const glm::dvec3 extent = (glm::dvec3(v.dims) - 1.0) * v.spacing;
    p.width = std::max(1, int(std::floor(extent[a] / p.pixelSize + 1e-9)) + 1);
    p.height = std::max(1, int(std::floor(extent[b] / p.pixelSize + 1e-9)) + 1);
    glm::dvec3 idx = (glm::dvec3(v.dims) - 1.0) * 0.5;
    idx[axis] = index;
    p.point = v.world(idx);
    // Pixel centres fall on voxel centres where the in-plane spacing is the smallest.
    p.point[a] = v.origin[a] + 0.5 * (p.width - 1) * p.pixelSize;
    p.point[b] = v.origin[b] + 0.5 * (p.height - 1) * p.pixelSize;
    return p;
}

Image curvedPlanarReformation(const FieldView& field, const std::vector<glm::dvec3>& curve,
                              const glm::dvec3& lateral, int width, double pixelSize) {
    if (curve.size() < 2) throw Error("a curve needs at least two points");
    if (width < 1 || width > 32768) throw Error("CPR width must be between 1 and 32768 pixels");
    if (!(pixelSize > 0)) throw Error("CPR pixel size must be positive");
    if (!(glm::length(lateral) > 0)) throw Error("CPR lateral direction must not be zero");
    std::vector<double> arc(curve.size(), 0.0);
    for (std::size_t n = 1; n < curve.size(); ++n)
        arc[n] = arc[n - 1] + glm::length(curve[n] - curve[n - 1]);
    const double total = arc.back();
    if (!(total > 0)) throw Error("the curve has zero length");
    const int height = std::max(1, int(std::floor(total / pixelSize)));
    if (height > 32768) throw Error("the curve is longer than 32768 pixels at this pixel size");
    // Per row: the curve point and the lateral direction (the previous one where the tangent
    // is parallel to `lateral`).
    std::vector<glm::dvec3> at(height), side(height);
    glm::dvec3 previous = glm::normalize(lateral);
    std::size_t seg = 1;
    for (int y = 0; y < height; ++y) {
        const double s = (y + 0.5) * pixelSize;
        while (seg + 1 < curve.size() && arc[seg] < s) ++seg;
        const double len = arc[seg] - arc[seg - 1];
        const double f = len > 0 ? (s - arc[seg - 1]) / len : 0.0;
        at[y] = curve[seg - 1] + f * (curve[seg] - curve[seg - 1]);
        const glm::dvec3 t = glm::normalize(curve[seg] - curve[seg - 1]);
        glm::dvec3 u = lateral - glm::dot(lateral, t) * t;
        if (glm::length(u) > 1e-9 * glm::length(lateral)) previous = glm::normalize(u);
        side[y] = previous;
    }
    Image image(width, height);
    forRows(field, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const glm::dvec3 w = at[y] + (x + 0.5 - 0.5 * width) * pixelSize * side[y];
            image.at(x, y) = glm::vec4(glm::vec3(float(field(w))), 1.0f);
        }
    });
    return image;
}

}  // namespace splat
