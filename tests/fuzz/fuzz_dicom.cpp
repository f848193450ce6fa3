// libFuzzer target: one DICOM file (.dcm) through GDCM and the series assembly.
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto p = splat::fuzz::writeFile(
        "in.dcm", std::string_view(reinterpret_cast<const char*>(data), size));
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string()); });
    return 0;
}
