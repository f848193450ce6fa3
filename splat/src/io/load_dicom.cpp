// DICOM series through GDCM: one series of a folder chosen (LoadOptions::dicomSeries, CLI
// --series UID, when a folder holds several), its files checked against each other and
// assembled into a volume. Values become real units (Hounsfield units for CT) through each
// file's rescale. The pieces are in dicom_detail.h.
#include <algorithm>
#include <cmath>

#include "dicom_detail.h"

namespace fs = std::filesystem;

namespace splat::detail {
namespace {

/// Background value: the padding value where the file says it, else the
/// rescaled minimum for CT; other modalities take the common rule (volumeBackground).
void setBackground(Volume& v, const SliceInfo& first) {
    if (first.padding) {
        v.background = float(first.slope * *first.padding + first.intercept);
        v.backgroundSource = "DICOM Pixel Padding Value";
    } else if (first.modality == "CT") {
        v.background = volumeStats(v, 1).minValue;
        v.backgroundSource = "minimum of the CT data (no Pixel Padding Value)";
    }
}

/// A Siemens mosaic: one file holds a volume, its n = NumberOfImagesInMosaic slices tiled
/// m x m (m = ceil(sqrt n)) in one image, row by row; read as nibabel's MosaicWrapper reads
/// it (geometry: mosaicGeometry). A series of mosaic files is a time series in
/// InstanceNumber order: LoadOptions::time picks the file (the first by default, with a
/// warning).
Volume loadMosaic(const std::string& name, std::vector<SliceInfo> files,
                  const LoadOptions& options) {
    std::vector<std::string> notes;
    std::stable_sort(files.begin(), files.end(), [](const SliceInfo& a, const SliceInfo& b) {
        return a.instance < b.instance;
    });
    const std::uint64_t step = timeStep(name, options, files.size());
    if (files.size() > 1 && !options.time)
        notes.push_back("Siemens mosaic series of " + std::to_string(files.size()) +
                        " files (one volume each): only the first was loaded (--time T loads "
                        "another)");
    const SliceInfo& s = files[step];
    const std::string sn = displayName(s.path);
    if (s.mosaicImages < 1)
        throw Error(sn +
                    ": Siemens mosaic DICOM (ImageType MOSAIC) without NumberOfImagesInMosaic "
                    "in its CSA image header: the slices tiled in its " +
                    std::to_string(s.columns) + " x " + std::to_string(s.rows) +
                    " image cannot be told apart");
    const int m = int(std::ceil(std::sqrt(double(s.mosaicImages)) - 1e-9));
    if (s.rows % m != 0 || s.columns % m != 0)
        throw Error(sn + ": Siemens mosaic of " + std::to_string(s.mosaicImages) +
                    " images does not tile its " + std::to_string(s.columns) + " x " +
                    std::to_string(s.rows) + " image in " + std::to_string(m) + " x " +
                    std::to_string(m) + " tiles");
    const int tileRows = s.rows / m, tileCols = s.columns / m;
    const glm::ivec3 dims(tileCols, tileRows, s.mosaicImages);
    checkedVoxelCount(dims, name);

    std::vector<float> image(std::size_t(s.rows) * std::size_t(s.columns));
    readPixels(s, image.data());
    Volume v = makeVolume(dims, glm::dvec3(1.0), name);
    for (int k = 0; k < dims.z; ++k) {
        const int r0 = (k / m) * tileRows, c0 = (k % m) * tileCols;
        for (int j = 0; j < tileRows; ++j)
            std::copy_n(image.data() + std::size_t(r0 + j) * std::size_t(s.columns) + c0, tileCols,
                        v.data.data() + v.index(0, j, k));
    }

    const DicomGeometry g = mosaicGeometry(s, tileRows, tileCols);
    notes.insert(notes.end(), g.notes.begin(), g.notes.end());
    std::string modality = s.modality.empty() ? "" : s.modality + " ";
    v.source = "DICOM " + modality + "Siemens mosaic, " + std::to_string(dims.z) + " slices (" +
               name + ")";
    if (files.size() > 1 && options.time)
        v.source += ", time step " + std::to_string(step) + " of " + std::to_string(files.size());
    applyOrientation(v, g.M, g.t, g.what);
    for (const std::string& n : notes) addNote(v, n);
    setBackground(v, s);
    return v;
}

}  // namespace

Volume loadDicomFiles(const std::string& name, const std::vector<fs::path>& files,
                      const LoadOptions& options) {
    if (files.empty()) throw Error(name + ": no DICOM files");
    std::vector<SliceInfo> all = readInfos(files);

    // One series.
    std::vector<DicomSeriesInfo> series = groupSeries(all);
    std::string uid = options.dicomSeries;
    if (uid.empty()) {
        if (series.size() > 1) {
            std::string list;
            for (const auto& d : series) list += (list.empty() ? "" : ", ") + d.uid;
            throw Error(name + ": holds " + std::to_string(series.size()) +
                        " DICOM series; choose one with --series UID (" + list +
                        "; `splat info` lists them)");
        }
        uid = series.front().uid;
    } else if (std::none_of(series.begin(), series.end(),
                            [&](const auto& d) { return d.uid == uid; })) {
        throw Error(name + ": no DICOM series with SeriesInstanceUID " + uid);
    }
    std::vector<SliceInfo> slices;
    for (SliceInfo& s : all)
        if (s.uid == uid) slices.push_back(std::move(s));

    const SliceInfo& first = slices.front();
    for (const SliceInfo& s : slices) {
        const std::string sn = displayName(s.path);
        if (s.mosaic != first.mosaic)
            throw Error(sn + ": series mixes Siemens mosaic and single-slice DICOM files");
        if (s.frames != 1)
            throw Error(sn + ": multi-frame DICOM (" + std::to_string(s.frames) +
                        " frames) is not supported");
        if (s.samples != 1)
            throw Error(sn + ": DICOM with " + std::to_string(s.samples) +
                        " samples per pixel is not supported (need scalar data)");
        if (s.rows < 1 || s.columns < 1)
            throw Error(sn + ": DICOM file has no Rows/Columns (no image?)");
        // The pixels a slice declares must fit its file (with room for 64:1 compression):
        // a 100-byte file cannot make us allocate gigabytes.
        const std::uint64_t pixelBytes =
            checkedMul(checkedMul(std::uint64_t(s.rows), std::uint64_t(s.columns), sn),
                       std::uint64_t(std::clamp(s.bitsAllocated, 8, 64) / 8), sn);
        if (pixelBytes > 64 * s.fileSize + (1u << 20))
            throw Error(sn + ": DICOM Rows x Columns " + std::to_string(s.rows) + " x " +
                        std::to_string(s.columns) + " needs more pixel data than the " +
                        std::to_string(s.fileSize) + "-byte file can hold");
        if (s.rows != first.rows || s.columns != first.columns)
            throw Error(sn + ": slice is " + std::to_string(s.columns) + " x " +
                        std::to_string(s.rows) + ", the first slice is " +
                        std::to_string(first.columns) + " x " + std::to_string(first.rows));
    }
    if (first.mosaic) return loadMosaic(name, std::move(slices), options);
    timeStep(name, options, 1);  // a series of single slices has no time axis
    if (slices.size() > std::size_t(INT32_MAX)) throw Error(name + ": too many slices");
    const glm::ivec3 dims(first.columns, first.rows, int(slices.size()));
    checkedVoxelCount(dims, name);
    DicomGeometry g = seriesGeometry(name, uid, slices);

    Volume v = makeVolume(dims, glm::dvec3(1.0), name);
    const std::size_t plane = std::size_t(dims.x) * std::size_t(dims.y);
    for (std::size_t k = 0; k < slices.size(); ++k)
        readPixels(slices[k], v.data.data() + k * plane);
    std::string modality = first.modality.empty() ? "" : first.modality + " ";
    v.source =
        "DICOM " + modality + "series, " + std::to_string(slices.size()) + " files (" + name + ")";
    applyOrientation(v, g.M, g.t, g.what);
    for (const std::string& n : g.notes) addNote(v, n);
    setBackground(v, first);
    return v;
}

}  // namespace splat::detail
