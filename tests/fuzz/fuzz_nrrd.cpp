// libFuzzer target: NRRD. An input holding the data marker (fuzz_util.h) is a detached
// header (.nhdr) plus its data file "data.raw" in the same folder; otherwise an attached
// .nrrd.
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto p = splat::fuzz::writeHeaderAndData(
        std::string_view(reinterpret_cast<const char*>(data), size), "in.nrrd", "in.nhdr");
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string()); });
    return 0;
}
