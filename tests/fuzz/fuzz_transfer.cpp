// libFuzzer target: transfer-function JSON files (TransferFunction::load). The library does
// not parse scene files (the CLI does), so this is the one JSON format fuzzed here.
#include "fuzz_util.h"
#include "splat/transfer.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto p = splat::fuzz::writeFile(
        "tf.json", std::string_view(reinterpret_cast<const char*>(data), size));
    splat::fuzz::expectOnlySplatErrors([&] { splat::TransferFunction::load(p.string()); });
    return 0;
}
