// libFuzzer target: MetaImage. An input holding the data marker (fuzz_util.h) is a .mhd
// header plus its data file "data.raw"; otherwise a single .mha.
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view in(reinterpret_cast<const char*>(data), size), header, payload;
    std::filesystem::path p;
    if (splat::fuzz::splitData(in, header, payload)) {
        splat::fuzz::writeFile("data.raw", payload);
        p = splat::fuzz::writeFile("in.mhd", header);
    } else {
        p = splat::fuzz::writeFile("in.mha", in);
    }
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string()); });
    return 0;
}
