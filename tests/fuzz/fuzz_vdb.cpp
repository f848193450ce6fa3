// libFuzzer target: OpenVDB files (built when splat has OpenVDB, SPLAT_OPENVDB). Seeds:
// tests/sparse/make_sparse_data.py's .vdb files (tools/fuzz.sh).
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto p = splat::fuzz::writeFile(
        "in.vdb", std::string_view(reinterpret_cast<const char*>(data), size));
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string()); });
    return 0;
}
