// Reading a brick, or the outer faces, of a volume file from its sample layout
// (sample_layout.h): byte ranges of a raw-stored file (pread), or the wanted bytes of a
// compressed file's stream, decompressed from the start and kept only where wanted.
#include "sample_layout.h"

#include <bzlib.h>
#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <memory>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace fs = std::filesystem;

namespace splat::detail {

std::uint64_t SampleLayout::sampleBytes() const {
    return std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z) * sampleSize(type);
}

bool SampleLayout::scaled() const {
    return std::isfinite(slope) && slope != 0.0 && (slope != 1.0 || inter != 0.0);
}

namespace {

std::string boxText(const glm::ivec3& lo, const glm::ivec3& hi) {
    return std::to_string(lo.x) + "," + std::to_string(lo.y) + "," + std::to_string(lo.z) + " to " +
           std::to_string(hi.x - 1) + "," + std::to_string(hi.y - 1) + "," +
           std::to_string(hi.z - 1);
}

/// An open file read by position, closed on destruction.
class File {
  public:
    File(const fs::path& p, const std::string& name) : name_(name) {
        fd_ = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) throw Error(name + ": cannot read (" + std::strerror(errno) + ")");
    }
    ~File() { ::close(fd_); }
    File(const File&) = delete;
    File& operator=(const File&) = delete;
    /// Up to n bytes at `at`; fewer only at the end of the file.
    std::size_t read(std::uint64_t at, std::size_t n, unsigned char* out) const {
        std::size_t got = 0;
        while (got < n) {
            const ssize_t r = ::pread(fd_, out + got, n - got, off_t(at + got));
            if (r < 0 && errno == EINTR) continue;
            if (r < 0) throw Error(name_ + ": cannot read bytes " + std::to_string(at) + " on");
            if (r == 0) break;
            got += std::size_t(r);
        }
        return got;
    }

  private:
    int fd_ = -1;
    std::string name_;
};

/// The sample bytes of a layout, read at increasing offsets (counted from the first sample).
/// Raw: pread. Compressed: the stream is decompressed from its start, and what lies before
/// a wanted range is decompressed into a scratch buffer and dropped.
class SampleBytes {
  public:
    explicit SampleBytes(const SampleLayout& L) : L_(L), file_(L.file, L.fileName) {
        if (L.codec == SampleLayout::Codec::None) return;
        in_.resize(1 << 20);
        scratch_.resize(1 << 20);
        if (L.codec == SampleLayout::Codec::Gzip) {
            if (inflateInit2(&zs_, 15 + 32) != Z_OK)
                throw Error(L.fileName + ": cannot initialise zlib");
        } else if (BZ2_bzDecompressInit(&bz_, 0, 0) != BZ_OK) {
            throw Error(L.fileName + ": cannot initialise bzip2");
        }
        open_ = true;
    }
    ~SampleBytes() { end(); }
    SampleBytes(const SampleBytes&) = delete;
    SampleBytes& operator=(const SampleBytes&) = delete;

    bool compressed() const { return L_.codec != SampleLayout::Codec::None; }

    /// n bytes at sample byte `at`; false when the data end first.
    bool read(std::uint64_t at, std::size_t n, unsigned char* out) {
        if (!compressed()) return file_.read(L_.start + at, n, out) == n;
        const std::uint64_t target = L_.skip + at;
        if (target < pos_) throw Error(L_.fileName + ": internal error: stream read backwards");
        while (pos_ < target) {
            const std::size_t want =
                std::size_t(std::min<std::uint64_t>(target - pos_, scratch_.size()));
            const std::size_t got = produce(scratch_.data(), want);
            if (got == 0) return false;
        }
        std::size_t done = 0;
        while (done < n) {
            const std::size_t got = produce(out + done, n - done);
            if (got == 0) return false;
            done += got;
        }
        return true;
    }

    /// Compressed: the bytes the stream holds from here to its end (it is decompressed on).
    std::uint64_t drain() {
        while (produce(scratch_.data(), scratch_.size()) > 0) {
        }
        return pos_;
    }
    std::uint64_t position() const { return pos_; }

  private:
    /// Up to n decompressed bytes into out; 0 at the end of the data.
    std::size_t produce(unsigned char* out, std::size_t n) {
        if (done_) return 0;
        const bool gz = L_.codec == SampleLayout::Codec::Gzip;
        std::size_t made = 0;
        while (made == 0) {
            if ((gz ? zs_.avail_in : bz_.avail_in) == 0 && inPos_ < L_.streamBytes) {
                const std::size_t want =
                    std::size_t(std::min<std::uint64_t>(in_.size(), L_.streamBytes - inPos_));
                const std::size_t got = file_.read(L_.start + inPos_, want, in_.data());
                if (got < want) inEnd_ = true;
                inPos_ += got;
                if (gz) {
                    zs_.next_in = in_.data();
                    zs_.avail_in = uInt(got);
                } else {
                    bz_.next_in = reinterpret_cast<char*>(in_.data());
                    bz_.avail_in = unsigned(got);
                }
                if (got == 0) inEnd_ = true;
            }
            if (inPos_ >= L_.streamBytes) inEnd_ = true;
            const std::size_t room = std::min<std::size_t>(n, 1u << 30);
            int ret;
            std::size_t got;
            bool streamEnd;
            if (gz) {
                zs_.next_out = out;
                zs_.avail_out = uInt(room);
                ret = inflate(&zs_, Z_NO_FLUSH);
                got = room - zs_.avail_out;
                streamEnd = ret == Z_STREAM_END;
                // Z_BUF_ERROR: no progress; an error only when no input is left to give.
                if (ret == Z_BUF_ERROR && zs_.avail_in == 0 && inEnd_)
                    fail("unexpected end of stream");
                if (ret != Z_OK && ret != Z_STREAM_END && ret != Z_BUF_ERROR)
                    fail(zs_.msg ? zs_.msg : "error");
            } else {
                bz_.next_out = reinterpret_cast<char*>(out);
                bz_.avail_out = unsigned(room);
                ret = BZ2_bzDecompress(&bz_);
                got = room - bz_.avail_out;
                streamEnd = ret == BZ_STREAM_END;
                if (ret != BZ_OK && ret != BZ_STREAM_END) fail("error " + std::to_string(ret));
            }
            made = got;
            pos_ += got;
            const std::size_t left = gz ? zs_.avail_in : bz_.avail_in;
            if (streamEnd) {
                // Concatenated gzip members and bzip2 streams are legal: the next one.
                if (left > 0 || !inEnd_) {
                    restart();
                    continue;
                }
                done_ = true;
                return made;
            }
            if (got == 0 && left == 0 && inEnd_) fail("unexpected end of stream");
        }
        return made;
    }

    void restart() {
        if (L_.codec == SampleLayout::Codec::Gzip) {
            if (inflateReset(&zs_) != Z_OK) fail("error");
            return;
        }
        const unsigned left = bz_.avail_in;
        char* next = bz_.next_in;
        BZ2_bzDecompressEnd(&bz_);
        bz_ = bz_stream{};
        if (BZ2_bzDecompressInit(&bz_, 0, 0) != BZ_OK) fail("error");
        bz_.next_in = next;
        bz_.avail_in = left;
    }

    [[noreturn]] void fail(const std::string& reason) {
        throw Error(L_.fileName + ": corrupt " +
                    (L_.codec == SampleLayout::Codec::Gzip ? "gzip" : "bzip2") + " data (" +
                    reason + ")");
    }

    void end() {
        if (!open_) return;
        if (L_.codec == SampleLayout::Codec::Gzip)
            inflateEnd(&zs_);
        else
            BZ2_bzDecompressEnd(&bz_);
        open_ = false;
    }

    const SampleLayout& L_;
    File file_;
    std::vector<unsigned char> in_, scratch_;
    z_stream zs_{};
    bz_stream bz_{};
    bool open_ = false, done_ = false, inEnd_ = false;
    std::uint64_t inPos_ = 0;  ///< compressed bytes read from `start`
    std::uint64_t pos_ = 0;    ///< decompressed bytes produced
};

/// Decodes n samples of `bytes` to float as the loaders do (type, byte order, scaling).
void decodeRow(const SampleLayout& L, const unsigned char* bytes, std::size_t n, float* out) {
    decodeSamples(bytes, n, L.type, L.bigEndian, out);
    if (L.scaled())
        for (std::size_t i = 0; i < n; ++i) out[i] = float(L.slope * out[i] + L.inter);
}

/// The whole-file size checks of the loaders, for a raw-stored layout.
void checkWholeRaw(const SampleLayout& L) {
    const std::uint64_t size = regularFileSize(L.file);
    const std::uint64_t available = size > L.start ? size - L.start : 0;
    checkDataLength(std::size_t(L.sampleBytes()), std::size_t(available), L.fileName, L.exact);
}

/// After the last sample of a compressed layout: the loaders' checks on what follows.
void checkWholeStream(const SampleLayout& L, SampleBytes& bytes) {
    const std::uint64_t wanted = L.skip + L.sampleBytes();
    const std::uint64_t held = bytes.drain();
    if (L.exact && held > wanted)
        throw Error(L.fileName + ": compressed data holds more data than the header declares (" +
                    std::to_string(wanted) + " bytes)");
}

}  // namespace

Volume layoutGeometry(const SampleLayout& L) {
    Volume g;
    g.dims = L.dims;
    g.spacing = glm::dvec3(1.0);
    g.source = L.source;
    applyOrientation(g, L.M, L.t, L.orientation);  // no samples: the geometry alone
    for (const std::string& n : L.notes) addNote(g, n);
    return g;
}

Volume readLayoutBrick(const SampleLayout& L, const Volume& whole, const glm::ivec3& lo,
                       const glm::ivec3& hi, NonFinitePolicy policy) {
    const AxisMap map = axisMapOf(L.M, L.source, L.orientation);
    const glm::ivec3 n = hi - lo;
    // The brick's box in the file's index order, and where a step along each file axis
    // goes in the brick (applyOrientation's permutation, restricted to the box).
    glm::ivec3 flo, fhi;
    std::ptrdiff_t step[3], first = 0;
    for (int a = 0; a < 3; ++a) {
        const int w = map.axis[std::size_t(a)];
        std::ptrdiff_t s = w == 0 ? 1 : w == 1 ? std::ptrdiff_t(n.x) : std::ptrdiff_t(n.x) * n.y;
        if (map.sign[a] > 0) {
            flo[a] = lo[w];
            fhi[a] = hi[w];
        } else {
            flo[a] = L.dims[a] - hi[w];
            fhi[a] = L.dims[a] - lo[w];
            first += s * (fhi[a] - flo[a] - 1);
            s = -s;
        }
        step[a] = s;
    }
    Volume v = makeVolume(n, whole.spacing, whole.source);
    v.origin = whole.world(glm::dvec3(lo));
    v.direction = whole.direction;
    v.background = whole.background;
    v.backgroundSource = whole.backgroundSource;
    v.note = whole.note;

    const std::size_t ss = sampleSize(L.type);
    const std::uint64_t rowBytes = std::uint64_t(L.dims.x) * ss;
    const std::uint64_t sliceBytes = rowBytes * std::uint64_t(L.dims.y);
    const std::uint64_t lastByte = std::uint64_t(fhi.z - 1) * sliceBytes +
                                   std::uint64_t(fhi.y - 1) * rowBytes + std::uint64_t(fhi.x) * ss;
    SampleBytes bytes(L);
    auto beyond = [&](std::uint64_t held) {
        const std::uint64_t base = bytes.compressed() ? L.skip : L.start;
        return Error(L.fileName + ": truncated data: the brick of samples " + boxText(lo, hi) +
                     " ends at byte " + std::to_string(base + lastByte) + ", the " +
                     (bytes.compressed() ? "decompressed data hold " : "file holds ") +
                     std::to_string(held));
    };
    if (!bytes.compressed() && L.start + lastByte > regularFileSize(L.file))
        throw beyond(regularFileSize(L.file));

    const std::size_t nx = std::size_t(fhi.x - flo.x);
    std::vector<unsigned char> raw(nx * ss);
    std::vector<float> row(nx);
    for (int k = flo.z; k < fhi.z; ++k)
        for (int j = flo.y; j < fhi.y; ++j) {
            const std::uint64_t at = std::uint64_t(k) * sliceBytes + std::uint64_t(j) * rowBytes +
                                     std::uint64_t(flo.x) * ss;
            if (!bytes.read(at, raw.size(), raw.data())) {
                if (!bytes.compressed()) throw beyond(regularFileSize(L.file));
                throw beyond(bytes.drain());
            }
            decodeRow(L, raw.data(), nx, row.data());
            std::ptrdiff_t dst = first + step[1] * (j - flo.y) + step[2] * (k - flo.z);
            for (std::size_t i = 0; i < nx; ++i, dst += step[0]) v.data[std::size_t(dst)] = row[i];
        }
    applyNonFinitePolicy(v, policy, L.name);
    return v;
}

float layoutBackground(const SampleLayout& L, NonFinitePolicy policy) {
    SampleBytes bytes(L);
    if (!bytes.compressed()) checkWholeRaw(L);
    const glm::ivec3 d = L.dims;
    const std::size_t ss = sampleSize(L.type);
    const std::uint64_t rowBytes = std::uint64_t(d.x) * ss;
    std::vector<unsigned char> raw{};
    raw.resize(std::size_t(rowBytes));
    std::vector<float> row(std::size_t(d.x));
    std::vector<float> face;
    auto keep = [&](float x) {
        if (std::isfinite(x))
            face.push_back(x);
        else if (policy == NonFinitePolicy::Zero)
            face.push_back(0.0f);  // as loadVolume replaces it before the rule
        // NonFinitePolicy::Error: the brick that holds it fails; the rule skips it.
    };
    auto need = [&](bool ok) {
        if (ok) return;
        if (bytes.compressed())
            checkDataLength(std::size_t(L.skip + L.sampleBytes()), std::size_t(bytes.drain()),
                            L.fileName, true);
        throw Error(L.fileName + ": cannot read (the file shrank while reading?)");
    };
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j) {
            const std::uint64_t at =
                (std::uint64_t(k) * std::uint64_t(d.y) + std::uint64_t(j)) * rowBytes;
            const bool wholeRow = k == 0 || k == d.z - 1 || j == 0 || j == d.y - 1;
            if (wholeRow || d.x <= 2) {
                need(bytes.read(at, raw.size(), raw.data()));
                decodeRow(L, raw.data(), std::size_t(d.x), row.data());
                for (float x : row) keep(x);
                continue;
            }
            // The first and last sample of an inner row.
            need(bytes.read(at, ss, raw.data()));
            need(bytes.read(at + rowBytes - ss, ss, raw.data() + ss));
            decodeRow(L, raw.data(), 2, row.data());
            keep(row[0]);
            keep(row[1]);
        }
    if (bytes.compressed()) checkWholeStream(L, bytes);
    if (face.empty()) return 0.0f;
    auto mid = face.begin() + std::ptrdiff_t(face.size() / 2);
    std::nth_element(face.begin(), mid, face.end());
    return *mid;
}

SampleLayout rawSampleLayout(const fs::path& p, const RawOptions& options) {
    const RawLayout R = rawLayout(p, options);
    const bool gz = lowerExtension(p) == ".raw.gz";
    SampleLayout L;
    L.file = p;
    L.fileName = displayName(p);
    L.codec = gz ? SampleLayout::Codec::Gzip : SampleLayout::Codec::None;
    if (gz)
        L.skip = R.offset;
    else
        L.start = R.offset;
    L.exact = true;
    L.dims = R.dims;
    L.type = R.type;
    L.bigEndian = options.bigEndian;
    const glm::dvec3 s = options.spacing.value_or(glm::dvec3(1.0));
    L.M = glm::dmat3(s.x, 0, 0, 0, s.y, 0, 0, 0, s.z);
    L.name = L.fileName;
    L.source =
        std::string("raw ") + sampleTypeName(R.type) +
        (sampleSize(R.type) > 1 ? (options.bigEndian ? " big-endian" : " little-endian") : "") +
        (gz ? " gzip" : "") + " (" + p.filename().string() + ")";
    return L;
}

bool sampleLayoutOf(const std::string& spec, const LoadOptions& options, SampleLayout* layout) {
    if (spec.rfind("synthetic:", 0) == 0 || spec.empty()) return false;
    const fs::path p(spec);
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) return false;
    std::string ext = lowerExtension(p);
    std::optional<SampleLayout> L;
    if (ext == ".nii" || ext == ".nii.gz") {
        L = niftiLayout(p, options);
    } else if (ext == ".nrrd" || ext == ".nhdr") {
        L = nrrdLayout(p, options);
    } else if (ext == ".mhd" || ext == ".mha") {
        timeStep(displayName(p), options, 1);  // no time axis
        L = metaImageLayout(p, options);
    } else if (ext == ".raw" || ext == ".raw.gz") {
        timeStep(displayName(p), options, 1);
        L = rawSampleLayout(p, options.raw);
    }
    if (!L) return false;
    *layout = std::move(*L);
    return true;
}

}  // namespace splat::detail
