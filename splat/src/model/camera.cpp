// Orthographic and perspective cameras following docs/design.md's convention.
#include "splat/camera.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "splat/error.h"

namespace splat {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxImageSide = 32768;
constexpr std::int64_t kMaxImagePixels = std::int64_t(1) << 27;  // 2 GiB of RGBA floats
}  // namespace

CameraParams interpolateCamera(const CameraParams& a, const CameraParams& b, double t) {
    if (a.width != b.width || a.height != b.height)
        throw Error("camera path: views of different image sizes cannot be interpolated");
    if (a.projection != b.projection)
        throw Error("camera path: orthographic and perspective views cannot be interpolated");
    if (a.lookAtSet != b.lookAtSet)
        throw Error(
            "camera path: an orbit view and a free (eye/look-at) view cannot be "
            "interpolated");
    if (!(t >= 0.0 && t <= 1.0)) throw Error("camera interpolation: t must be in [0, 1]");
    if (t == 0.0) return a;
    if (t == 1.0) return b;
    auto lerp = [t](auto x, auto y) { return x + (y - x) * t; };
    CameraParams c = a;
    c.azimuthDeg = lerp(a.azimuthDeg, b.azimuthDeg);
    c.elevationDeg = lerp(a.elevationDeg, b.elevationDeg);
    c.distance = lerp(a.distance, b.distance);
    c.pixelSize = lerp(a.pixelSize, b.pixelSize);
    c.fovDeg = lerp(a.fovDeg, b.fovDeg);
    c.eye = lerp(a.eye, b.eye);
    c.lookAt = lerp(a.lookAt, b.lookAt);
    c.upHint = lerp(a.upHint, b.upHint);
    return c;
}

Camera::Camera(const CameraParams& params, const Volume& volume) : params_(params) {
    if (params.width < 1 || params.height < 1 || params.width > kMaxImageSide ||
        params.height > kMaxImageSide)
        throw Error("image size " + std::to_string(params.width) + "x" +
                    std::to_string(params.height) + " is outside 1.." +
                    std::to_string(kMaxImageSide) + " per side");
    if (std::int64_t(params.width) * params.height > kMaxImagePixels)
        throw Error("image size " + std::to_string(params.width) + "x" +
                    std::to_string(params.height) + " exceeds " +
                    std::to_string(kMaxImagePixels >> 20) + " Mpixels");
    if (!std::isfinite(params.azimuthDeg) || !std::isfinite(params.elevationDeg))
        throw Error("azimuth and elevation must be finite numbers");
    if (!(params.distance >= 0) || !std::isfinite(params.distance))
        throw Error("camera distance must be a finite number of world units >= 0 (0 = fit)");
    if (!(params.pixelSize >= 0) || !std::isfinite(params.pixelSize))
        throw Error("pixel size must be a positive number of world units (0 = fit)");
    if (params.projection == Projection::Perspective &&
        !(params.fovDeg > 0.1 && params.fovDeg < 170))
        throw Error("perspective field of view must be between 0.1 and 170 degrees");

    boundingRadius = 0.5 * glm::length(glm::dvec3(volume.dims) * volume.spacing);
    const double side = double(std::min(params.width, params.height));
    // The one place where the world frame meets the volume's frame (docs/design.md "World frame"):
    // the parameters are world (RAS), the renderers work in the volume's frame, world = direction *
    // frame, so world points and directions turn by direction^T. For an oblique volume this is a
    // change of basis of the view, not a resampling of the data.
    const glm::dmat3 toFrame = glm::transpose(volume.direction);
    if (params.lookAtSet) {
        CameraParams p = params;
        p.eye = toFrame * params.eye;
        p.lookAt = toFrame * params.lookAt;
        p.upHint = toFrame * params.upHint;
        lookAtCamera(p, volume, side);
        return;
    }
    const double a = params.azimuthDeg * kPi / 180.0, e = params.elevationDeg * kPi / 180.0;
    view =
        toFrame * glm::dvec3(-std::sin(a) * std::cos(e), std::cos(a) * std::cos(e), -std::sin(e));
    right = toFrame * glm::dvec3(std::cos(a), std::sin(a), 0.0);
    up = glm::cross(right, view);

    target = volume.center();
    if (params.projection == Projection::Orthographic) {
        pixelSize = params.pixelSize > 0 ? params.pixelSize : 2.0 * boundingRadius / side;
        eye = target - view * (1.5 * boundingRadius + 1.0);
        focal = glm::length(target - eye);
    } else {
        const double half = 0.5 * params.fovDeg * kPi / 180.0;
        focal = params.distance > 0 ? params.distance : boundingRadius / std::sin(half) + 1e-9;
        eye = target - view * focal;
        pixelSize = params.pixelSize > 0 ? params.pixelSize : 2.0 * focal * std::tan(half) / side;
    }
}

void Camera::lookAtCamera(const CameraParams& p, const Volume& volume, double side) {
    auto finite = [](const glm::dvec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    if (!finite(p.eye) || !finite(p.lookAt) || !finite(p.upHint))
        throw Error("camera eye, look-at point and up vector must be finite");
    const glm::dvec3 d = p.lookAt - p.eye;
    const double dist = glm::length(d);
    if (!(dist > 0)) throw Error("camera eye and look-at point must differ");
    view = d / dist;
    const glm::dvec3 r = glm::cross(view, p.upHint);
    if (!(glm::length(r) > 1e-9 * glm::length(p.upHint)) || !(glm::length(p.upHint) > 0))
        throw Error("camera up vector must not be zero or parallel to the view direction");
    right = glm::normalize(r);
    up = glm::cross(right, view);
    target = p.lookAt;
    const glm::dvec3 centre = volume.center();
    if (p.projection == Projection::Orthographic) {
        pixelSize = p.pixelSize > 0 ? p.pixelSize : 2.0 * boundingRadius / side;
        // Rays start on a plane in front of the whole volume (its bounding sphere).
        const double back = glm::dot(target - centre, view) + 1.5 * boundingRadius + 1.0;
        eye = target - view * std::max(back, 1.0);
        focal = glm::length(target - eye);
    } else {
        const double half = 0.5 * p.fovDeg * kPi / 180.0;
        eye = p.eye;
        focal = dist;
        pixelSize = p.pixelSize > 0 ? p.pixelSize : 2.0 * focal * std::tan(half) / side;
    }
}

Ray Camera::ray(double px, double py) const {
    const double sx = (px - 0.5 * params_.width) * pixelSize;
    const double sy = (py - 0.5 * params_.height) * pixelSize;
    if (!perspective()) return {eye + right * sx - up * sy, view};
    return {eye, glm::normalize(view * focal + right * sx - up * sy)};
}

glm::dvec3 Camera::project(const glm::dvec3& world) const {
    const glm::dvec3 d = world - eye;
    const double depth = glm::dot(d, view);
    const double scale = perspective() ? focal / depth : 1.0;
    return {0.5 * params_.width + glm::dot(d, right) * scale / pixelSize,
            0.5 * params_.height - glm::dot(d, up) * scale / pixelSize, depth};
}

}  // namespace splat
