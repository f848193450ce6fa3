// The geometry of a DICOM series: the files of one series are sorted by their position
// along the slice normal (row direction x column direction), the slice spacing is the mean
// gap between neighbours (uneven gaps are refused, a gantry tilt is warned about), and the
// LPS patient coordinates become the RAS world NIfTI uses, so the same orientation code
// makes a head upright. A Siemens mosaic's slices are placed as nibabel's MosaicWrapper
// places them.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "dicom_detail.h"

namespace splat::detail {
namespace {

std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

}  // namespace

DicomGeometry seriesGeometry(const std::string& name, const std::string& uid,
                             std::vector<SliceInfo>& slices) {
    const SliceInfo& first = slices.front();  // the front after each sort below
    std::vector<std::string> notes;
    // In-plane spacing: PixelSpacing is (row spacing, column spacing) = (dy, dx).
    double dx = 1, dy = 1;
    if (first.pixelSpacing) {
        dy = (*first.pixelSpacing)[0];
        dx = (*first.pixelSpacing)[1];
        for (const SliceInfo& s : slices)
            if (!s.pixelSpacing || *s.pixelSpacing != *first.pixelSpacing)
                throw Error(displayName(s.path) + ": DICOM PixelSpacing differs between slices");
    } else {
        notes.push_back("DICOM: no PixelSpacing, 1 x 1 mm pixels assumed");
    }

    // Order and slice spacing from the geometry when every slice has it.
    const bool geometry = std::all_of(slices.begin(), slices.end(), [](const SliceInfo& s) {
        return s.position && s.orientation;
    });
    glm::dmat3 M(1.0);
    glm::dvec3 t(0.0);
    std::string what = "DICOM ImageOrientationPatient";
    if (geometry) {
        const std::vector<double>& o = *first.orientation;
        glm::dvec3 r(o[0], o[1], o[2]), c(o[3], o[4], o[5]);
        if (!(glm::length(r) > 0.5) || !(glm::length(c) > 0.5) ||
            std::abs(glm::dot(glm::normalize(r), glm::normalize(c))) > 1e-3)
            throw Error(displayName(first.path) +
                        ": DICOM ImageOrientationPatient is not two orthogonal unit vectors");
        // The file's r and c as given (PS3.3 C.7.6.2.1.1's equation, as nibabel and pydicom
        // use them; their rounding in the file is not normalised away), the normal unit.
        const glm::dvec3 r0 = r, c0 = c;
        r = glm::normalize(r);
        c = glm::normalize(c);
        const glm::dvec3 n = glm::cross(r, c);
        for (const SliceInfo& s : slices) {
            const std::vector<double>& so = *s.orientation;
            for (int i = 0; i < 6; ++i)
                if (std::abs(so[std::size_t(i)] - o[std::size_t(i)]) > 1e-4)
                    throw Error(displayName(s.path) +
                                ": DICOM ImageOrientationPatient differs between slices");
        }
        std::stable_sort(slices.begin(), slices.end(), [&](const SliceInfo& a, const SliceInfo& b) {
            return glm::dot(*a.position, n) < glm::dot(*b.position, n);
        });
        double gap = 1;
        glm::dvec3 step = n;
        if (slices.size() > 1) {
            double lo = INFINITY, hi = 0;
            for (std::size_t k = 1; k < slices.size(); ++k) {
                const double g = glm::dot(*slices[k].position - *slices[k - 1].position, n);
                lo = std::min(lo, g);
                hi = std::max(hi, g);
            }
            if (!(lo > 1e-6))
                throw Error(name + ": two DICOM slices of series " + uid +
                            " lie at the same position (several acquisitions in one series?)");
            if (hi > lo * 1.01 + 1e-4)
                throw Error(name + ": uneven DICOM slice gaps in series " + uid + " (from " +
                            fmt(lo) + " to " + fmt(hi) +
                            " mm: missing slices?); a volume needs one slice spacing");
            const glm::dvec3 span = *slices.back().position - *slices.front().position;
            gap = glm::dot(span, n) / double(slices.size() - 1);
            step = span / double(slices.size() - 1);
            const double tilt = std::acos(std::min(1.0, glm::dot(glm::normalize(step), n)));
            if (tilt > 1e-3)
                notes.push_back("DICOM gantry tilt of " + fmt(tilt * 180.0 / M_PI) +
                                " degrees: slices are stacked along the normal, not sheared");
        } else if (first.between && *first.between > 0) {
            gap = *first.between;
        } else if (first.thickness && *first.thickness > 0) {
            gap = *first.thickness;
        }
        // Columns (index x) run along r, rows (index y) along c, slices along n; LPS
        // patient coordinates become RAS (x and y negated), the convention of NIfTI.
        const glm::dmat3 lpsToRas(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1));
        M = lpsToRas * glm::dmat3(r0 * dx, c0 * dy, n * gap);
        t = lpsToRas * *slices.front().position;
    } else {
        const bool numbered = std::all_of(slices.begin(), slices.end(),
                                          [](const SliceInfo& s) { return s.instance >= 0; });
        if (numbered)
            std::stable_sort(
                slices.begin(), slices.end(),
                [](const SliceInfo& a, const SliceInfo& b) { return a.instance < b.instance; });
        double gap = 1;
        if (first.between && *first.between > 0)
            gap = *first.between;
        else if (first.thickness && *first.thickness > 0)
            gap = *first.thickness;
        M = glm::dmat3(glm::dvec3(dx, 0, 0), glm::dvec3(0, dy, 0), glm::dvec3(0, 0, gap));
        what = "DICOM spacing";
        notes.push_back(std::string("DICOM: no ImagePositionPatient/ImageOrientationPatient, "
                                    "slices ordered by ") +
                        (numbered ? "InstanceNumber" : "file name") + ", slice spacing " +
                        fmt(gap) + " assumed, orientation unknown");
    }
    return {M, t, what, notes};
}

/// ImagePositionPatient is that of the whole tiled image's first pixel, so the first slice's
/// is moved by half the difference between the mosaic's and a tile's size along the rows
/// and columns; slices are stacked along the slice normal (the sign of the CSA
/// SliceNormalVector) at SpacingBetweenSlices (else SliceThickness).
DicomGeometry mosaicGeometry(const SliceInfo& s, int tileRows, int tileCols) {
    const std::string sn = displayName(s.path);
    std::vector<std::string> notes;
    double dx = 1, dy = 1;
    if (s.pixelSpacing) {
        dy = (*s.pixelSpacing)[0];
        dx = (*s.pixelSpacing)[1];
    } else {
        notes.push_back("DICOM: no PixelSpacing, 1 x 1 mm pixels assumed");
    }
    double gap = 1;
    if (s.between && *s.between > 0)
        gap = *s.between;
    else if (s.thickness && *s.thickness > 0)
        gap = *s.thickness;
    glm::dmat3 M(glm::dvec3(dx, 0, 0), glm::dvec3(0, dy, 0), glm::dvec3(0, 0, gap));
    glm::dvec3 t(0.0);
    std::string what = "DICOM spacing";
    if (s.position && s.orientation) {
        const std::vector<double>& o = *s.orientation;
        glm::dvec3 r(o[0], o[1], o[2]), c(o[3], o[4], o[5]);
        if (!(glm::length(r) > 0.5) || !(glm::length(c) > 0.5) ||
            std::abs(glm::dot(glm::normalize(r), glm::normalize(c))) > 1e-3)
            throw Error(sn + ": DICOM ImageOrientationPatient is not two orthogonal unit vectors");
        // nibabel: the normal from the orientation (r, c as given), its sign from the CSA
        // SliceNormalVector (without one, column x row direction).
        glm::dvec3 n = glm::cross(r, c);
        if (s.csaNormal ? glm::dot(n, *s.csaNormal) < 0 : true) n = -n;
        const glm::dvec3 first = *s.position + r * (dx * double(s.columns - tileCols) / 2) +
                                 c * (dy * double(s.rows - tileRows) / 2);
        const glm::dmat3 lpsToRas(glm::dvec3(-1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, 1));
        M = lpsToRas * glm::dmat3(r * dx, c * dy, n * gap);
        t = lpsToRas * first;
        what = "DICOM ImageOrientationPatient";
    } else {
        notes.push_back(
            "DICOM: no ImagePositionPatient/ImageOrientationPatient, orientation "
            "unknown");
    }
    return {M, t, what, notes};
}

}  // namespace splat::detail
