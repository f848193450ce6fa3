// libFuzzer target: OME-Zarr / Zarr v2. The input is a `.zarray` (JSON), kDataMarker
// (fuzz_util.h) and the bytes of chunk 0.0.0: written as the folder in.zarr, loaded whole.
// Seeds: tests/sparse/make_sparse_data.py's arrays (tools/fuzz.sh).
#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace fs = std::filesystem;
    const std::string_view in(reinterpret_cast<const char*>(data), size);
    std::string_view meta, chunk;
    const bool hasChunk = splat::fuzz::splitData(in, meta, chunk);
    const fs::path dir = splat::fuzz::scratch() / "in.zarr";
    fs::remove_all(dir);
    fs::create_directories(dir);
    splat::fuzz::writeFile("in.zarr/.zarray", meta);
    if (hasChunk) splat::fuzz::writeFile("in.zarr/0.0.0", chunk);
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(dir.string()); });
    return 0;
}
