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
    // GDCM's RLE decoder aborts on this file (an assertion in gdcm::Attribute): one line.
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "rtdose_rle_1frame.dcm").string()); }),
               Catch::EndsWith("rtdose_rle_1frame.dcm: malformed DICOM file (GDCM decoding the "
                               "compressed pixels died on it with SIGABRT, a failed assertion)"));
    // An undefined-length UN sequence (PS3.5 6.2.2: implicit VR inside) passes the element
    // walk: the refusal is about the missing image, not the structure.
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "UN_sequence.dcm").string()); }),
               Catch::Contains("no Rows/Columns"));
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "nested_priv_SQ.dcm").string()); }),
               Catch::Contains("no Rows/Columns"));
    // A truncated file: the tag in hex, as DICOM writes it.
    CHECK_THAT(errorOf([&] { loadVolume((kPydicom / "MR_truncated.dcm").string()); }),
               Catch::Contains("element (7fe0,0010) declares 8192 bytes, the file holds 8130"));
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
