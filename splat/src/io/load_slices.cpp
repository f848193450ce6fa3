// Folders of 2D slices: PNG/TIFF stacks read through OpenImageIO (one image per z,
// natural sort order so that slice2 comes before slice10); folders of DICOM files go to
// the GDCM reader (load_dicom.cpp); a folder of 3D volume files (NIfTI, NRRD, MetaImage) is a
// time series, one step per file in natural order (LoadOptions::time picks it).
//
// Slice pixel (column c, row r) of the n-th slice becomes voxel (c, r, n); values keep
// their native range (0..255 for 8-bit, 0..65535 for 16-bit images); colour images
// are reduced to Rec. 709 luminance. Spacing is 1 unless the files say otherwise.
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstring>

#include "splat/error.h"
#include "volume_detail.h"

namespace fs = std::filesystem;
OIIO_NAMESPACE_USING

namespace splat::detail {
namespace {

/// A 3D volume file of a time-series folder (the header of a pair: .hdr, .nhdr, .mhd).
bool isVolumeFile(const fs::path& p) {
    std::string e = toLower(p.extension().string());
    if (e == ".gz") e = toLower(p.stem().extension().string()) + e;
    return e == ".nii" || e == ".nii.gz" || e == ".hdr" || e == ".nrrd" || e == ".nhdr" ||
           e == ".mha" || e == ".mhd";
}

bool isSliceImage(const fs::path& p) {
    std::string e = toLower(p.extension().string());
    return e == ".png" || e == ".tif" || e == ".tiff";
}

std::optional<SampleType> oiioSampleType(TypeDesc t) {
    if (t == TypeDesc::UINT8) return SampleType::U8;
    if (t == TypeDesc::INT8) return SampleType::I8;
    if (t == TypeDesc::UINT16) return SampleType::U16;
    if (t == TypeDesc::INT16) return SampleType::I16;
    if (t == TypeDesc::UINT32) return SampleType::U32;
    if (t == TypeDesc::INT32) return SampleType::I32;
    if (t == TypeDesc::FLOAT) return SampleType::F32;
    if (t == TypeDesc::DOUBLE) return SampleType::F64;
    return std::nullopt;  // half and others: read as float
}

// Copies one slice into the volume at depth k, checking its size.
void placeSlice(Volume& v, int k, const std::vector<float>& slice, glm::ivec2 size,
                const fs::path& file) {
    if (size.x != v.dims.x || size.y != v.dims.y)
        throw Error(displayName(file) + ": slice is " + std::to_string(size.x) + " x " +
                    std::to_string(size.y) + ", the first slice is " + std::to_string(v.dims.x) +
                    " x " + std::to_string(v.dims.y));
    std::copy(slice.begin(), slice.end(), v.data.begin() + std::ptrdiff_t(v.index(0, 0, k)));
}

}  // namespace

glm::ivec2 readImageSlice(const fs::path& p, std::vector<float>& out, std::string* formatName) {
    const std::string name = displayName(p);
    auto in = ImageInput::open(p.string());
    if (!in) {
        std::string err = OIIO::geterror();
        throw Error(name + ": cannot read image" + (err.empty() ? "" : " (" + err + ")"));
    }
    const ImageSpec& spec = in->spec();
    if (spec.depth > 1) throw Error(name + ": 3D image files are not supported as slices");
    if (formatName) *formatName = in->format_name();
    auto type = oiioSampleType(spec.format);
    TypeDesc readAs = type ? spec.format : TypeDesc::FLOAT;
    SampleType decodeAs = type ? *type : SampleType::F32;
    const int nc = spec.nchannels;
    const std::size_t pixels = std::size_t(spec.width) * std::size_t(spec.height);
    std::vector<unsigned char> raw(pixels * std::size_t(nc) * readAs.size());
    if (!in->read_image(0, 0, 0, nc, readAs, raw.data()))
        throw Error(name + ": cannot read image data (" + in->geterror() + ")");
    in->close();
    std::vector<float> all(pixels * std::size_t(nc));
    decodeSamples(raw.data(), all.size(), decodeAs, false, all.data());  // OIIO gives host order
    out.resize(pixels);
    for (std::size_t i = 0; i < pixels; ++i) {
        const float* px = &all[i * std::size_t(nc)];
        out[i] = nc >= 3 ? 0.2126f * px[0] + 0.7152f * px[1] + 0.0722f * px[2] : px[0];
    }
    return {spec.width, spec.height};
}

// DICOM files: ".dcm"/".dicom" or the "DICM" magic after the 128-byte preamble.
bool isDicomFile(const fs::path& p) {
    std::string e = toLower(p.extension().string());
    if (e == ".dcm" || e == ".dicom") return true;
    std::FILE* f = std::fopen(p.string().c_str(), "rb");
    if (!f) return false;
    char magic[4] = {};
    bool ok = std::fseek(f, 128, SEEK_SET) == 0 && std::fread(magic, 1, 4, f) == 4 &&
              std::memcmp(magic, "DICM", 4) == 0;
    std::fclose(f);
    return ok;
}

Volume loadSliceFolder(const fs::path& dir, const LoadOptions& options) {
    const std::string name = displayName(dir);
    std::vector<fs::path> images, dicoms, volumes;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
        if (!entry.is_regular_file()) continue;
        const fs::path& p = entry.path();
        if (p.filename().string().starts_with(".")) continue;
        if (isSliceImage(p))
            images.push_back(p);
        else if (isVolumeFile(p))
            volumes.push_back(p);
        else if (isDicomFile(p))
            dicoms.push_back(p);
    }
    if (ec) throw Error(name + ": cannot list folder (" + ec.message() + ")");
    auto byName = [](const fs::path& a, const fs::path& b) {
        return naturalLess(a.filename().string(), b.filename().string());
    };
    if (images.empty() && !dicoms.empty()) {
        std::sort(dicoms.begin(), dicoms.end(), byName);
        return loadDicomFiles(name, dicoms, options);
    }
    if (images.empty() && !volumes.empty()) {
        std::sort(volumes.begin(), volumes.end(), byName);
        const std::uint64_t step = timeStep(name, options, volumes.size());
        LoadOptions one = options;
        one.time.reset();  // the step is the file; a 4D file in it gives its first volume
        Volume v = loadVolume(volumes[step].string(), one);
        v.source += ", time step " + std::to_string(step) + " of " +
                    std::to_string(volumes.size()) + " (" + name + ")";
        if (!options.time && volumes.size() > 1)
            addNote(v, "folder of " + std::to_string(volumes.size()) +
                           " volume files, a time series: only the first was loaded (--time T "
                           "loads another)");
        return v;
    }
    if (images.empty())
        throw Error(name + ": folder holds no PNG/TIFF slices, DICOM files or volume files");
    timeStep(name, options, 1);  // a stack of slices has no time axis
    std::sort(images.begin(), images.end(), byName);

    std::vector<float> slice;
    glm::ivec2 size = readImageSlice(images[0], slice);
    if (images.size() > std::size_t(INT32_MAX)) throw Error(name + ": too many slices");
    Volume v = makeVolume({size.x, size.y, int(images.size())}, glm::dvec3(1.0), name);
    placeSlice(v, 0, slice, size, images[0]);
    for (std::size_t k = 1; k < images.size(); ++k) {
        size = readImageSlice(images[k], slice);
        placeSlice(v, int(k), slice, size, images[k]);
    }
    v.source = "slice folder, " + std::to_string(images.size()) + " images (" +
               images.front().filename().string() + " .. " + images.back().filename().string() +
               ")";
    return v;
}

}  // namespace splat::detail
