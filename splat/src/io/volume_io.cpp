// loadVolume: picks the loader for a VOLUME argument (synthetic:, folder, extension,
// or the file's magic bytes) and applies the NaN/Inf policy to every loaded volume.
#include "splat/volume_io.h"

#include <cmath>
#include <cstring>
#include <fstream>

#include "splat/error.h"
#include "splat/synthetic.h"
#include "io/vdb/openvdb_file.h"
#include "volume_detail.h"
#include "io/zarr/ome_zarr.h"

namespace fs = std::filesystem;

namespace splat {
namespace {

Volume loadSynthetic(const std::string& spec) {
    const auto [name, n] = detail::syntheticSpec(spec);
    return makeSynthetic(name, n);
}

// Content sniffing for files whose extension says nothing.
std::string sniff(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    char head[352] = {};
    in.read(head, sizeof head);
    std::size_t got = std::size_t(in.gcount());
    if (got >= 4 && std::string(head, 4) == "NRRD") return ".nrrd";
    if (got >= 348 && (std::string(head + 344, 4) == std::string("n+1\0", 4))) return ".nii";
    if (got >= 12 && std::string(head + 4, 4) == std::string("n+2\0", 4)) return ".nii";
    if (got >= 132 && std::string(head + 128, 4) == "DICM") return ".dcm";
    std::string text(head, got);
    if (text.find("ObjectType") != std::string::npos || text.rfind("NDims", 0) == 0) return ".mha";
    return "";
}

}  // namespace

void detail::applyNonFinitePolicy(Volume& v, NonFinitePolicy policy, const std::string& what) {
    std::size_t count = 0, first = 0;
    for (std::size_t i = 0; i < v.data.size(); ++i)
        if (!std::isfinite(v.data[i])) {
            if (count++ == 0) first = i;
            if (policy == NonFinitePolicy::Zero) v.data[i] = 0.0f;
        }
    if (count == 0) return;
    if (policy == NonFinitePolicy::Error) {
        std::size_t nx = std::size_t(v.dims.x), ny = std::size_t(v.dims.y);
        throw Error(what + ": " + std::to_string(count) + " NaN/Inf samples (first at voxel " +
                    std::to_string(first % nx) + "," + std::to_string(first / nx % ny) + "," +
                    std::to_string(first / (nx * ny)) +
                    "); use --nan-policy zero to replace them by 0");
    }
    if (!v.note.empty()) v.note += "; ";
    v.note += std::to_string(count) + " NaN/Inf samples replaced by 0";
}

std::uint64_t detail::timeStep(const std::string& name, const LoadOptions& options,
                               std::uint64_t steps) {
    if (!options.time) return 0;
    if (*options.time >= 0 && std::uint64_t(*options.time) < steps)
        return std::uint64_t(*options.time);
    throw OptionError(name + ": time step " + std::to_string(*options.time) + " is out of range: " +
                      (steps == 1 ? std::string("it holds one volume (time step 0)")
                                  : "it holds time steps 0 to " + std::to_string(steps - 1)));
}

namespace {

Volume loadByType(const fs::path& p, const std::string& ext, const LoadOptions& options) {
    if (ext == ".nii" || ext == ".nii.gz" || ext == ".hdr" || ext == ".img")
        return detail::loadNifti(p, options);
    if (ext == ".nrrd" || ext == ".nhdr") return detail::loadNrrd(p, options);
    if (ext == ".mhd" || ext == ".mha" || ext == ".raw" || ext == ".raw.gz")
        detail::timeStep(detail::displayName(p), options, 1);  // no time axis
    if (ext == ".mhd" || ext == ".mha") return detail::loadMetaImage(p, options);
    if (ext == ".raw" || ext == ".raw.gz") return detail::loadRaw(p, options.raw);
    if (ext == ".vdb") return detail::loadVdb(p, options);
    if (ext == ".dcm" || ext == ".dicom")
        return detail::loadDicomFiles(detail::displayName(p), {p}, options);
    if (ext == ".png" || ext == ".tif" || ext == ".tiff")
        throw Error(detail::displayName(p) +
                    ": a single 2D image; give the folder of slices instead");
    return Volume{};
}

}  // namespace

std::pair<std::string, int> detail::syntheticSpec(const std::string& spec) {
    // synthetic:NAME[:N]
    std::string rest = spec.substr(std::strlen("synthetic:"));
    std::string name = rest;
    int n = 0;
    std::size_t colon = rest.find(':');
    if (colon != std::string::npos) {
        name = rest.substr(0, colon);
        std::string num = rest.substr(colon + 1);
        char* end = nullptr;
        long value = std::strtol(num.c_str(), &end, 10);
        if (num.empty() || *end || value < 1 || value > 2048)
            throw Error(spec + ": size must be an integer between 1 and 2048");
        n = int(value);
    } else {
        n = syntheticDefaultSize(name);
    }
    return {name, n};
}

Volume loadVolume(const std::string& spec, const LoadOptions& options) {
    Volume v;
    if (spec.rfind("synthetic:", 0) == 0) {
        detail::timeStep(spec, options, 1);
        v = loadSynthetic(spec);
    } else {
        if (spec.empty()) throw Error("empty VOLUME argument");
        fs::path p(spec);
        std::error_code ec;
        fs::file_status st = fs::status(p, ec);
        if (!fs::exists(st)) throw Error(spec + ": no such file or folder");
        if (fs::is_directory(st)) {
            v = detail::isZarrFolder(p) ? detail::loadZarr(p, options)
                                        : detail::loadSliceFolder(p, options);
        } else {
            detail::regularFileSize(p);  // FIFOs and devices are refused before any open
            std::string ext = lowerExtension(p);
            // .hdr.gz / .img.gz pairs: the extension before .gz decides.
            if (ext == ".gz") ext = lowerExtension(p.stem());
            v = loadByType(p, ext, options);
            if (!v.hasSamples()) {
                std::string guess = sniff(p);
                if (guess.empty() || guess == ext)
                    throw Error(spec + ": unknown file type '" + p.extension().string() +
                                "' (expected .nii, .nii.gz, .hdr/.img, .nrrd, .nhdr, .mhd, .mha, "
                                ".raw, .raw.gz, .dcm, .vdb, a folder of slices or DICOM files, "
                                "an OME-Zarr folder, or synthetic:NAME)");
                v = loadByType(p, guess, options);
            }
        }
    }
    detail::applyNonFinitePolicy(v, options.nonFinite, spec);
    // Background value b: a loader that read it from the file said so; otherwise
    // the common rule, and synthetic volumes (made around an empty 0) keep 0.
    if (v.backgroundSource == Volume{}.backgroundSource) {
        if (spec.rfind("synthetic:", 0) == 0) {
            v.backgroundSource = "synthetic volume";
        } else {
            v.background = backgroundFromFaces(v);
            v.backgroundSource = "median of the outer faces";
        }
    }
    return v;
}

}  // namespace splat
