#pragma once
// A scalar volume: samples d_i at integer index positions p = (i, j, k), position
// x = origin + S p with S = diag(spacing) in the volume's frame, world position
// R x with R = direction (a rotation; the identity unless the file is oblique). World is
// RAS+ millimetres (NIfTI's frame; every loader converts into it). Samples are x fastest,
// then y, then z; stored as float in `data` (owned), or in the caller's memory or a file's
// type (u8/i16/u16/f32, read as raw * scale + offset) without a float copy: Volume::borrow.
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

namespace splat {

/// Largest number of voxels a volume may hold (2^32, 16 GiB of floats); larger requests
/// are refused with a clear error rather than attempted.
inline constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 32;

/// How samples are stored. Every reader converts through Volume::value (float), so a
/// renderer never makes a float copy of a borrowed or typed volume.
enum class SampleType : std::uint8_t { Float32, UInt8, Int16, UInt16 };
/// Bytes per sample of `type` (4, 1, 2, 2).
std::size_t sampleTypeBytes(SampleType type);
/// "float32", "uint8", "int16", "uint16".
const char* sampleTypeName(SampleType type);

struct Volume {
    glm::ivec3 dims{0};       ///< samples along x, y, z (all >= 1 for a valid volume)
    glm::dvec3 spacing{1.0};  ///< world units (usually mm) between samples per axis
    glm::dvec3 origin{0.0};   ///< position of sample (0, 0, 0) in the volume's frame
    /// Rotation from the volume's frame to the world frame (RAS): world = direction * x for
    /// a volume-frame position x. Loaders put here what is left of a file's index-to-world
    /// affine after the nearest axis permutation and flips (an oblique acquisition); the
    /// renderers work in the volume's frame and the Camera turns its world parameters into
    /// it (docs/design.md "World frame"). Identity: the volume frame is the world frame.
    glm::dmat3 direction{1.0};
    /// The samples of an owned float volume: dims.x * dims.y * dims.z, x fastest (the
    /// loaders fill it). Empty for a borrowed or typed volume (sampleData() is then the
    /// storage); read samples with at() or value(), which work for every storage.
    std::vector<float> data;
    std::string source;  ///< how it was obtained, e.g. "NIfTI-1 int16 (ch2.nii.gz)"
    /// Warnings about the input, "; " separated: anything accepted with an assumption or
    /// an ignored field (sheared axes made a rotation, 4D file's first volume, DICOM gantry
    /// tilt, NaNs replaced, ...). Every command prints it (docs/input-files.md lists the cases).
    std::string note;
    /// Background value b (docs/design.md "Reconstructed fields"): what the data
    /// hold where nothing is (air at -1000 HU in CT, 0 in MR magnitude and signed fields).
    /// The reconstructed field is f(x) = b + sum_i (d_i - b) h(x - x_i): it tends to b
    /// outside the volume and across clipped regions, and "empty" means "equal to b".
    float background = 0.0f;
    /// Where `background` came from, printed by `splat info`: e.g. "DICOM Pixel Padding
    /// Value", "median of the outer faces", "--background", "scene file".
    std::string backgroundSource = "default (0)";

    std::size_t voxelCount() const {
        return std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z);
    }
    std::size_t index(int i, int j, int k) const {
        return (std::size_t(k) * std::size_t(dims.y) + std::size_t(j)) * std::size_t(dims.x) +
               std::size_t(i);
    }
    /// A volume over samples the caller owns (no copy): dims.x*dims.y*dims.z samples of `type`,
    /// x fastest, read as value = raw * scale + offset. `keepAlive` (may be null) is held by the
    /// Volume and by every Scene/Renderer built from it; with a null keepAlive the caller
    /// guarantees the memory outlives them. Throws splat::Error on bad sizes/spacing/null data.
    static Volume borrow(const void* samples, SampleType type, const glm::ivec3& dims,
                         const glm::dvec3& spacing, const glm::dvec3& origin,
                         std::shared_ptr<const void> keepAlive = nullptr, double scale = 1.0,
                         double offset = 0.0);
    /// As borrow, over storage the volume owns through `storage` (a loader keeping a file's
    /// 8/16-bit samples): borrowed() is false.
    static Volume typed(std::shared_ptr<const void> storage, const void* samples, SampleType type,
                        const glm::ivec3& dims, const glm::dvec3& spacing, const glm::dvec3& origin,
                        double scale = 1.0, double offset = 0.0);

    SampleType sampleType() const { return external_ ? type_ : SampleType::Float32; }
    /// The first sample, whatever the storage (data.data() for an owned float volume).
    const void* sampleData() const { return external_ ? external_ : data.data(); }
    /// True for a volume made by borrow (its samples live in the caller's memory).
    bool borrowed() const { return borrowed_; }
    double sampleScale() const { return external_ ? scale_ : 1.0; }
    double sampleOffset() const { return external_ ? offset_ : 0.0; }
    /// True when the storage holds voxelCount() >= 1 samples.
    bool hasSamples() const {
        return voxelCount() > 0 && (external_ != nullptr || data.size() == voxelCount());
    }
    /// Sample n (index order) as float: raw * scale + offset, computed in double.
    float value(std::size_t n) const {
        if (!external_) return data[n];
        switch (type_) {
            case SampleType::Float32: {
                const float raw = static_cast<const float*>(external_)[n];
                return identity_ ? raw : float(double(raw) * scale_ + offset_);
            }
            case SampleType::UInt8:
                return float(double(static_cast<const std::uint8_t*>(external_)[n]) * scale_ +
                             offset_);
            case SampleType::Int16:
                return float(double(static_cast<const std::int16_t*>(external_)[n]) * scale_ +
                             offset_);
            case SampleType::UInt16:
                return float(double(static_cast<const std::uint16_t*>(external_)[n]) * scale_ +
                             offset_);
        }
        return 0.0f;
    }
    /// Samples [first, first + count) as float into `out` (one row at a time, say).
    void values(std::size_t first, std::size_t count, float* out) const;
    float at(int i, int j, int k) const { return value(index(i, j, k)); }
    /// Writable sample of an owned float volume (`data`); not for borrowed or typed storage.
    float& at(int i, int j, int k) { return data[index(i, j, k)]; }
    /// Volume-frame position of a (possibly fractional) index position: the renderers'
    /// coordinates (the world position when `direction` is the identity).
    glm::dvec3 world(const glm::dvec3& p) const { return origin + spacing * p; }
    /// World (RAS) position of a (possibly fractional) index position.
    glm::dvec3 worldPosition(const glm::dvec3& p) const { return direction * world(p); }
    /// True when `direction` is not the identity (an oblique volume).
    bool rotated() const { return direction != glm::dmat3(1.0); }
    /// World position of the volume centre, index (n - 1) / 2 on every axis.
    glm::dvec3 center() const { return world((glm::dvec3(dims) - 1.0) * 0.5); }
    /// Smallest spacing: the world length of "one voxel" in docs/design.md.
    double minSpacing() const { return glm::min(spacing.x, glm::min(spacing.y, spacing.z)); }
    /// Memory the samples take, in bytes (the caller's, for a borrowed volume).
    std::size_t bytes() const {
        return external_ ? voxelCount() * sampleTypeBytes(type_) : data.size() * sizeof(float);
    }

  private:
    const void* external_ = nullptr;         ///< borrowed or typed samples; null: `data`
    std::shared_ptr<const void> keepAlive_;  ///< owner of external_ (may be null if borrowed)
    SampleType type_ = SampleType::Float32;
    bool borrowed_ = false;
    bool identity_ = true;  ///< scale 1, offset 0
    double scale_ = 1.0, offset_ = 0.0;
};

/// The voxel count of `dims` after checking every dimension >= 1 and the count within
/// kMaxVoxels (64-bit, no wrap); throws splat::Error naming `what` otherwise.
std::uint64_t checkedVoxelCount(const glm::ivec3& dims, const std::string& what);

/// Allocates a zero-filled volume after validating its size: every dimension >= 1, the
/// voxel count within kMaxVoxels without overflow, spacings finite and > 0.
/// Throws splat::Error naming `what` (a file name or description) otherwise.
Volume makeVolume(const glm::ivec3& dims, const glm::dvec3& spacing, const std::string& what);

/// The default background value rule (docs/decisions.md): the median of the
/// finite samples on the volume's six outer faces. Right for CT in HU (air, about -1000, or
/// the scanner's padding fills the faces), MR magnitude (0) and signed fields such as phase
/// or velocity (0 around the object, not the minimum). Files that state a value (DICOM Pixel
/// Padding Value) and CT series use that instead; `splat info` prints which.
float backgroundFromFaces(const Volume& v);

/// True when the data look like CT in Hounsfield units: the background value lies in
/// [-3100, -900] (air at -1000 HU, or a scanner's padding down to -3024). The CLI then
/// renders dvr with the absolute preset `ct-hu` unless --tf chooses another.
bool looksLikeHounsfield(const Volume& v);

/// Statistics of a volume's samples.
struct VolumeStats {
    float minValue = 0, maxValue = 0;
    double mean = 0;
    std::vector<std::size_t> histogram;  ///< equal-width bins over [minValue, maxValue]
};
VolumeStats volumeStats(const Volume& v, int bins = 16);

/// Multi-line human description (`splat info`): dimensions, spacing, extent, source,
/// value range, mean, a text histogram and memory use.
std::string describeVolume(const Volume& v);

}  // namespace splat
