// libFuzzer target: NRRD. An input holding the data marker (fuzz_util.h) is a detached
// header (.nhdr) plus its data file "data.raw" in the same folder; otherwise an attached
// .nrrd.
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view in(reinterpret_cast<const char*>(data), size), header, payload;
    std::filesystem::path p;
    if (splat::fuzz::splitData(in, header, payload)) {
        splat::fuzz::writeFile("data.raw", payload);
        p = splat::fuzz::writeFile("in.nhdr", header);
    } else {
        p = splat::fuzz::writeFile("in.nrrd", in);
    }
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string()); });
    return 0;
}
