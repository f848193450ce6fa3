// Third-party DICOM files (Debian's python3-pydicom test data, installed by tools/setup.sh):
// compressed transfer syntaxes decode to the same values as the uncompressed original,
// GDCM aborting on a file is one error line, undefined-length UN and private sequences pass
// the element walk. Skipped with a message when pydicom's data is not installed.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>

#include "splat/volume_io.h"
#include "test_volume_util.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {
const fs::path kPydicom = "/usr/lib/python3/dist-packages/pydicom/data/test_files";
}

TEST_CASE("DICOM: compressed transfer syntaxes decode like the uncompressed file",
          "[volume][dicom][thirdparty]") {
    if (!fs::exists(kPydicom / "MR_small.dcm")) {
        WARN("skipped: python3-pydicom's test files are missing (tools/setup.sh)");
        return;
    }
    const Volume ref = loadVolume((kPydicom / "MR_small.dcm").string());
    REQUIRE(ref.dims == glm::ivec3(64, 64, 1));
    // MR_small in RLE, JPEG-LS lossless and JPEG 2000 lossless: identical voxels.
    for (const char* f :
         {"MR_small_RLE.dcm", "MR_small_jpeg_ls_lossless.dcm", "MR_small_jp2klossless.dcm"}) {
        INFO(f);
        const Volume v = loadVolume((kPydicom / f).string());
        REQUIRE(v.dims == ref.dims);
        CHECK(v.data == ref.data);
        CHECK(v.spacing == ref.spacing);
    }
    // JPEG 2000 with signed values (pydicom reads -3995 .. 1812, mean -1032.3228).
    const Volume j2k = loadVolume((kPydicom / "693_J2KI.dcm").string());
    REQUIRE(j2k.dims == glm::ivec3(512, 512, 1));
    double lo = 1e30, hi = -1e30, sum = 0;
    for (float x : j2k.data) {
        lo = std::min(lo, double(x));
        hi = std::max(hi, double(x));
        sum += x;
    }
    CHECK(lo == -3995);
    CHECK(hi == 1812);
    CHECK(sum / double(j2k.data.size()) == Approx(-1032.3228454589844).epsilon(1e-9));
}

TEST_CASE("DICOM: third-party files GDCM or splat cannot read are refused in one line",
          "[volume][dicom][thirdparty]") {
    if (!fs::exists(kPydicom / "MR_small.dcm")) {
        WARN("skipped: python3-pydicom's test files are missing (tools/setup.sh)");
        return;
    }
    // An undefined-length UN sequence (PS3.5 6.2.2: implicit VR inside) passes the element
    // walk: the refusal is about the missing image (no Pixel Data), not the structure.
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "UN_sequence.dcm").string()); }),
               Catch::EndsWith("UN_sequence.dcm: DICOM file without pixel data (no Pixel Data "
                               "element (7fe0,0010)): not an image"));
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "nested_priv_SQ.dcm").string()); }),
               Catch::Contains("no Rows/Columns"));
    // A truncated file: the tag in hex, as DICOM writes it.
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "MR_truncated.dcm").string()); }),
               Catch::Contains("element (7fe0,0010) declares 8192 bytes, the file holds 8130"));
}

TEST_CASE("DICOM: RLE Lossless decoded by splat as pydicom decodes it; files that are no image",
          "[volume][dicom][thirdparty]") {
    if (!fs::exists(kPydicom / "MR_small.dcm")) {
        WARN("skipped: python3-pydicom's test files are missing (tools/setup.sh)");
        return;
    }
    // 32-bit RLE (four segments a sample), on which GDCM's RLE decoder asserts: pydicom reads
    // 10 x 10 doses 795000 .. 1254000, mean 1013780, the first row starting 1249000 1249000
    // 1250000 1250000 1247000 (DoseGridScaling is no rescale: neither applies it).
    const Volume dose = loadVolume((kPydicom / "rtdose_rle_1frame.dcm").string());
    REQUIRE(dose.dims == glm::ivec3(10, 10, 1));
    double lo = 1e30, hi = -1e30, sum = 0;
    for (float x : dose.data) {
        lo = std::min(lo, double(x));
        hi = std::max(hi, double(x));
        sum += x;
    }
    CHECK(lo == 795000);
    CHECK(hi == 1254000);
    CHECK(sum == 101378000);
    // Its first row as stored (splat's axes may flip it: the row is found either way round).
    std::vector<float> row(dose.data.begin(), dose.data.begin() + 10);
    const std::vector<float> start = {1249000, 1249000, 1250000, 1250000, 1247000};
    bool found = false;
    for (int y = 0; y < 10 && !found; ++y) {
        std::vector<float> r(10), rr(10);
        for (int x = 0; x < 10; ++x) r[std::size_t(x)] = dose.at(x, y, 0);
        rr.assign(r.rbegin(), r.rend());
        found = std::equal(start.begin(), start.end(), r.begin()) ||
                std::equal(start.begin(), start.end(), rr.begin());
    }
    CHECK(found);
    // Four bytes of the JPEG 2000 codestream overwritten by a sequence delimiter (pydicom's
    // test of its fragment parser): the element walk reads the fragment by its length, and
    // the codestream's SIZ marker now declares another image, named in the refusal.
    CHECK_THAT(
        errorOf(
            [&] { loadVolume((kPydicom / "JPEG2000-embedded-sequence-delimiter.dcm").string()); }),
        Catch::EndsWith("JPEG2000-embedded-sequence-delimiter.dcm: corrupt JPEG 2000 codestream: "
                        "its SIZ marker declares a 3722445056 x 1024 image, the DICOM header "
                        "Columns x Rows 256 x 1024"));
    // A well-formed file without Pixel Data (nibabel's CSA header sample): one line.
    const fs::path csa =
        "/usr/lib/python3/dist-packages/nibabel/nicom/tests/data/csa_slice_norm.dcm";
    if (fs::exists(csa))
        CHECK_THAT(errorOf([&] { loadVolume(csa.string()); }),
                   Catch::EndsWith("csa_slice_norm.dcm: DICOM file without pixel data (no Pixel "
                                   "Data element (7fe0,0010)): not an image"));
    // A CIFTI-2 matrix is not a volume (nibabel's row_major.dconn.nii, intent code 3001).
    const fs::path cifti = "/usr/lib/python3/dist-packages/nibabel/tests/data/row_major.dconn.nii";
    if (fs::exists(cifti))
        CHECK_THAT(
            errorOf([&] { loadVolume(cifti.string()); }),
            Catch::EndsWith("row_major.dconn.nii: not a volume: a CIFTI-2 matrix (NIfTI "
                            "intent code 3001), whose axes are brain structures, not space"));
}

TEST_CASE("DICOM: Siemens mosaics are unpacked from the CSA header's image count",
          "[volume][dicom][thirdparty]") {
    const fs::path nib = "/usr/lib/python3/dist-packages/nibabel";
    if (!fs::exists(nib / "tests/data/0.dcm")) {
        WARN("skipped: python3-nibabel's test files are missing (tools/setup.sh)");
        return;
    }
    // 48 slices tiled 7 x 7 need a side divisible by 7; this 256 x 256 test image is not
    // (nibabel fails on it too): refused with that reason, not read as one flat slice.
    CHECK_THAT(errorOf([&] { loadVolume((nib / "tests/data/0.dcm").string()); }),
               Catch::EndsWith("0.dcm: Siemens mosaic of 48 images does not tile its 256 x 256 "
                               "image in 7 x 7 tiles"));
    // A DWI mosaic: 48 slices of 128 x 128 tiled 7 x 7 in 896 x 896 (nibabel's reading; the
    // conformance test compares every voxel position and the values with nibabel's).
    const fs::path dwi = testTmpDir("mosaic") / "siemens_dwi_1000.dcm";
    const std::string cmd = "gzip -dc '" +
                            (nib / "nicom/tests/data/siemens_dwi_1000.dcm.gz").string() + "' > '" +
                            dwi.string() + "'";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const Volume v = loadVolume(dwi.string());
    glm::ivec3 d = v.dims;
    std::sort(&d[0], &d[0] + 3);
    CHECK(d == glm::ivec3(48, 128, 128));
    CHECK_THAT(v.source, Catch::Contains("Siemens mosaic, 48 slices"));
}

TEST_CASE("DICOM: an implicit-VR data set under an explicit-VR syntax is refused by name",
          "[volume][dicom][thirdparty]") {
    if (!fs::exists(kPydicom / "SC_rgb_jpeg.dcm")) {
        WARN("skipped: python3-pydicom's test files are missing (tools/setup.sh)");
        return;
    }
    // JPEG baseline says explicit VR; the data set is implicit (pydicom guesses and reads it,
    // GDCM's recovery runs out of memory): the refusal names that, not an unknown VR.
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "SC_rgb_jpeg.dcm").string()); }),
               Catch::Contains("the data set is encoded in implicit VR, but its transfer syntax "
                               "1.2.840.10008.1.2.4.50 says explicit VR"));
}
