// Writes the seed corpora of the fuzz targets: `splat_fuzz_seeds OUTDIR` fills
// OUTDIR/<target>/ with small valid (and a few nearly valid) inputs of every shape each
// target understands, made by the library's own writers, GDCM's writer and by hand.
#include <bzlib.h>
#include <zlib.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../deflate_util.h"
#include "../dicom_util.h"
#include "fuzz_util.h"
#include "splat/volume_io.h"

namespace fs = std::filesystem;

namespace {

fs::path out;

void seed(const std::string& target, const std::string& name, const std::string& bytes) {
    fs::create_directories(out / target);
    std::ofstream f(out / target / name, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
}

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string gzip(const std::string& in) { return splat::test::deflateBytes(in, true); }

template <typename T>
std::string ramp(int n, T scale = T(1)) {
    std::string s;
    for (int i = 0; i < n; ++i) {
        T v = T(i) * scale;
        s.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: splat_fuzz_seeds OUTDIR\n");
        return 2;
    }
    out = argv[1];
    const fs::path tmp = splat::fuzz::scratch();
    const std::string marker(splat::fuzz::kDataMarker);

    // A small volume through the library's writers.
    splat::Volume v = splat::makeVolume({4, 3, 2}, {0.5, 1, 2}, "seed");
    for (std::size_t i = 0; i < v.data.size(); ++i) v.data[i] = float(i);
    v.origin = {1, -2, 3};
    splat::saveNifti((tmp / "v.nii").string(), v);
    const std::string nii = readAll(tmp / "v.nii");
    seed("nifti", "float32.nii", nii);
    seed("nifti_gz", "float32.nii", nii);
    splat::saveNrrd((tmp / "v.nrrd").string(), v);
    seed("nrrd", "float32.nrrd", readAll(tmp / "v.nrrd"));
    splat::saveMetaImage((tmp / "v.mha").string(), v);
    seed("metaimage", "float32.mha", readAll(tmp / "v.mha"));

    // NIfTI-1 int16 with a 4th dimension and scaling; NIfTI-2 (header patched by hand).
    {
        std::string h = nii.substr(0, 352);
        auto put16 = [&](std::size_t at, std::int16_t x) { std::memcpy(&h[at], &x, 2); };
        auto putf = [&](std::size_t at, float x) { std::memcpy(&h[at], &x, 4); };
        put16(40, 4);      // dim[0]
        put16(48, 2);      // dim[4]
        put16(70, 4);      // datatype int16
        put16(72, 16);     // bitpix
        putf(112, 2.0f);   // scl_slope
        putf(116, -1.0f);  // scl_inter
        seed("nifti", "int16_4d.nii", h + ramp<std::int16_t>(48));
        seed("nifti_gz", "int16_4d.nii", h + ramp<std::int16_t>(48));
    }

    // ANALYZE 7.5 pair: header (no NIfTI magic, vox_offset 0) + image.
    {
        std::string h = nii.substr(0, 348);
        std::memset(&h[344], 0, 4);
        const float zero = 0;
        std::memcpy(&h[108], &zero, 4);  // vox_offset
        seed("nifti", "analyze.hdr", h + marker + nii.substr(352));
    }

    // NRRD: attached gzip, text, big-endian with space directions; detached .nhdr.
    const std::string nrrdHead = "NRRD0004\ntype: short\ndimension: 3\nsizes: 4 3 2\n";
    seed("nrrd", "gzip.nrrd",
         nrrdHead + "endian: little\nencoding: gzip\nspacings: 1 2 nan\n\n" +
             gzip(ramp<std::int16_t>(24)));
    seed("nrrd", "text.nrrd",
         "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: text\n\n0 1 2 3 4 5 6 7\n");
    std::string be;
    for (int i = 0; i < 24; ++i) be += std::string{char(0), char(i)};
    seed("nrrd", "big.nrrd",
         nrrdHead +
             "endian: big\nencoding: raw\nspace: left-posterior-superior\n"
             "space directions: (0.5,0,0) (0,-1,0) (0,0,2)\nspace origin: (1,2,3)\n"
             "byte skip: 0\n\n" +
             be);
    // The other encodings: bzip2, hex; a time space and a left-handed one.
    {
        const std::string raw = ramp<std::int16_t>(24);
        const std::string skipped = "sk" + raw;  // byte skip 2 counts decompressed bytes
        std::vector<char> packed(raw.size() * 2 + 600);
        unsigned int packedSize = unsigned(packed.size());
        if (BZ2_bzBuffToBuffCompress(packed.data(), &packedSize, const_cast<char*>(skipped.data()),
                                     unsigned(skipped.size()), 9, 0, 0) == BZ_OK)
            seed("nrrd", "bzip2.nrrd",
                 nrrdHead + "endian: little\nencoding: bzip2\nbyte skip: 2\n\n" +
                     std::string(packed.data(), packedSize));
        static const char digits[] = "0123456789abcdef";
        std::string hex;
        for (std::size_t i = 0; i < raw.size(); ++i)
            hex += std::string{digits[(unsigned char)raw[i] >> 4], digits[raw[i] & 15],
                               i % 8 == 7 ? '\n' : ' '};
        seed("nrrd", "hex.nrrd",
             nrrdHead +
                 "endian: little\nencoding: hex\nspace: RAST\n"
                 "space directions: (0.5,0,0,0) (0,0.6,0.1,0) (0,0,2,0)\n"
                 "space origin: (1,2,3,0)\n\n" +
                 hex);
        seed("nrrd", "lefthanded.nrrd",
             nrrdHead +
                 "endian: little\nencoding: raw\nspace: 3D-left-handed\n"
                 "space directions: (0.9,0.1,0) (-0.1,0.9,0) (0,0,1)\n\n" +
                 raw);
    }
    seed("nrrd", "detached.nhdr",
         nrrdHead +
             "endian: little\nencoding: raw\nline skip: 1\nbyte skip: 2\n"
             "data file: data.raw\n" +
             marker + "skip\nxx" + ramp<std::int16_t>(24));
    seed("nrrd", "detached_gz.nhdr",
         nrrdHead + "endian: little\nencoding: gzip\ndata file: data.raw\n" + marker +
             gzip(ramp<std::int16_t>(24)));

    // MetaImage: .mha compressed, .mhd with a data file and HeaderSize.
    const std::string metaHead =
        "ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementType = MET_SHORT\n"
        "ElementSpacing = 0.5 0.5 2\nOffset = 1 2 3\n"
        "TransformMatrix = 1 0 0 0 -1 0 0 0 1\nAnatomicalOrientation = RPI\n";
    const std::string packed = gzip(ramp<std::int16_t>(24));
    seed("metaimage", "compressed.mha",
         metaHead + "CompressedData = True\nCompressedDataSize = " + std::to_string(packed.size()) +
             "\nElementDataFile = LOCAL\n" + packed);
    seed("metaimage", "separate.mhd",
         metaHead + "BinaryDataByteOrderMSB = False\nHeaderSize = 4\nElementDataFile = data.raw\n" +
             marker + "head" + ramp<std::int16_t>(24));
    seed("metaimage", "tail.mhd",
         metaHead + "HeaderSize = -1\nElementDataFile = data.raw\n" + marker + "junk" +
             ramp<std::int16_t>(24));

    // Raw by name.
    seed("raw", "int16.raw", "4x3x2_int16\n" + ramp<std::int16_t>(24));
    seed("raw", "float.raw", "2x2x2_float32 skip=4\nhead" + ramp<float>(8, 0.5f));
    seed("raw", "gz.raw", "2x2x2_uint8 gz\n" + gzip(ramp<std::uint8_t>(8)));

    // DICOM: a CT slice with position, orientation, spacing and rescale (GDCM's writer).
    splat::test::DicomSlice s;
    s.position = {-10, -20, 30};
    s.intercept = -1024;
    for (int i = 0; i < 12; ++i) s.stored.push_back(std::int16_t(1000 + i));
    splat::test::writeDicomSlice(tmp / "ct.dcm", s);
    seed("dicom", "ct.dcm", readAll(tmp / "ct.dcm"));
    s.orientation[4] = 0;  // oblique-ish and no rescale
    s.orientation[5] = 1;
    s.intercept = 0;
    splat::test::writeDicomSlice(tmp / "cor.dcm", s);
    seed("dicom", "coronal.dcm", readAll(tmp / "cor.dcm"));

    // Transfer functions.
    seed("transfer", "absolute.json",
         R"({"domain": "absolute", "unit_distance": 2.5, "points": [[0, 0, 0, 0, 0],)"
         R"( [100, 1, 0.5, 0.2, 0.3], [1000, 1, 1, 1, 1]]})");
    seed("transfer", "normalized.json",
         R"({"domain": "normalized", "points": [[0.0, 0, 0, 1, 0], [1.0, 1, 1, 1, 0.5]]})");
    fs::remove_all(tmp);
    std::printf("seeds written to %s\n", out.string().c_str());
    return 0;
}
