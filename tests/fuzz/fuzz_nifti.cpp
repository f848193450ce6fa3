// libFuzzer target: NIfTI-1/NIfTI-2 single files (.nii) from the fuzzer's bytes; an input
// holding the data marker (fuzz_util.h) is an ANALYZE 7.5 / NIfTI pair: header "in.hdr",
// image "in.img".
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto p = splat::fuzz::writeHeaderAndData(
        std::string_view(reinterpret_cast<const char*>(data), size), "in.nii", "in.hdr", "in.img");
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string()); });
    return 0;
}
