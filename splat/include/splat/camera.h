#pragma once
// The camera of docs/design.md "Camera convention": world z is up; azimuth a, elevation e give
// the view direction (-sin a cos e, cos a cos e, -sin e), image right (cos a, sin a, 0) and
// image up = right x view. The view is centred on the volume centre; pixel (0, 0) is the
// top-left corner and pixel centres sit at half-integers.
//
// CameraParams are world (RAS) quantities; a Camera's vectors and points are in the volume's
// frame (Volume::direction^T times world; the same as world unless the volume is oblique),
// the frame every renderer works in, so an oblique volume is seen in its true orientation.
#include <glm/glm.hpp>

#include "splat/volume.h"

namespace splat {

enum class Projection { Orthographic, Perspective };

struct CameraParams {
    int width = 512, height = 512;
    double azimuthDeg = 0, elevationDeg = 0;
    Projection projection = Projection::Orthographic;
    /// World units per pixel (orthographic; for perspective at the volume centre's depth).
    /// 0: fit the volume's bounding sphere into the smaller image side.
    double pixelSize = 0;
    /// Perspective: vertical field of view in degrees; the eye is placed so that the
    /// bounding sphere fits.
    double fovDeg = 30;
    /// Perspective: distance of the eye from the volume centre, world units (0: the
    /// distance at which the bounding sphere fits the field of view).
    double distance = 0;
    /// A free camera (as vtkCamera's position / focal point / view up), instead of the orbit
    /// about the volume centre: when `lookAtSet`, the view runs from `eye` towards `lookAt`
    /// (world), image up is `upHint` made perpendicular to the view, and azimuth, elevation
    /// and distance are unused. `lookAt` is the image centre (off-centre views); perspective
    /// rays start at `eye` (focal distance |lookAt - eye|), orthographic rays start in front
    /// of the whole volume. Default pixel size: as the orbit camera (the bounding sphere fits).
    bool lookAtSet = false;
    glm::dvec3 eye{0.0}, lookAt{0.0}, upHint{0.0, 0.0, 1.0};
};

/// The camera a fraction t in [0, 1] of the way from a to b (the popping analyzer's
/// refinement between two views of a camera path): every number interpolated linearly —
/// azimuth, elevation, distance, pixel size and field of view, and for a free camera eye,
/// look-at point and up vector — as CameraPath::fromJson interpolates between its keys.
/// t = 0 gives a, t = 1 gives b exactly. Throws splat::Error when a and b differ in what
/// cannot be interpolated: image size, projection, or orbit against free camera.
CameraParams interpolateCamera(const CameraParams& a, const CameraParams& b, double t);

struct Ray {
    glm::dvec3 origin, dir;  ///< dir is unit length
};

class Camera {
  public:
    Camera(const CameraParams& params, const Volume& volume);

    const CameraParams& params() const { return params_; }
    int width() const { return params_.width; }
    int height() const { return params_.height; }
    bool perspective() const { return params_.projection == Projection::Perspective; }

    glm::dvec3 right, up, view;  ///< unit vectors (volume frame); view points into the scene
    glm::dvec3 target;           ///< volume centre or look-at point (volume frame)
    glm::dvec3 eye;              ///< perspective eye (orthographic: target - view * radius)
    double pixelSize = 1;        ///< world units per pixel at the target's depth
    double focal = 1;            ///< perspective: distance of the target plane from the eye
    double boundingRadius = 0;   ///< of the volume (world)

    /// The ray through continuous pixel position (px, py) (pixel centres: x + 0.5).
    /// Orthographic rays start on the plane through the target, perpendicular to view,
    /// moved back by boundingRadius along -view; perspective rays start at the eye.
    Ray ray(double px, double py) const;
    /// Continuous pixel position (x, y) and depth of a world point; depth is the distance
    /// along view from the ray origin plane (orthographic) or from the eye (perspective).
    glm::dvec3 project(const glm::dvec3& world) const;

  private:
    void lookAtCamera(const CameraParams& p, const Volume& volume, double side);
    CameraParams params_;
};

}  // namespace splat
