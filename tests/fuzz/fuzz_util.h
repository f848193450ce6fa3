#pragma once
// Shared by the libFuzzer targets (tests/fuzz/fuzz_*.cpp): a private scratch folder per
// process, files written from the fuzzer's bytes, and the one rule every target checks:
// bad input may only end in splat::Error (anything else - a crash, a sanitizer report, a
// hang, an allocation beyond libFuzzer's -malloc_limit_mb - is a finding).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "splat/error.h"

namespace splat::fuzz {

/// This process's scratch folder (created once, under $TMPDIR or /tmp).
inline const std::filesystem::path& scratch() {
    static const std::filesystem::path dir = [] {
        const char* tmp = std::getenv("TMPDIR");
        std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/splat_fuzz_XXXXXX";
        if (!::mkdtemp(pattern.data())) std::abort();
        return std::filesystem::path(pattern);
    }();
    return dir;
}

inline std::filesystem::path writeFile(const std::string& name, std::string_view bytes) {
    std::filesystem::path p = scratch() / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    return p;
}

/// Runs f; splat::Error is the expected outcome of bad input, everything else escapes.
template <typename F>
void expectOnlySplatErrors(F f) {
    try {
        f();
    } catch (const splat::Error&) {
    }
}

/// The separator between a detached header and its data file in one fuzzer input (the
/// seeds use it; mutations may remove it, then the header has no data file).
inline constexpr std::string_view kDataMarker = "\n@@DATA@@\n";

/// Splits at kDataMarker: {header, data}; no marker -> {everything, nullopt-like empty}.
inline bool splitData(std::string_view in, std::string_view& header, std::string_view& data) {
    const std::size_t at = in.find(kDataMarker);
    if (at == std::string_view::npos) {
        header = in;
        data = {};
        return false;
    }
    header = in.substr(0, at);
    data = in.substr(at + kDataMarker.size());
    return true;
}

/// Writes an input for a format with attached or detached data: with kDataMarker, the
/// header as `detachedName` and the rest as "data.raw" beside it; otherwise all of it as
/// `singleName`. Returns the file to load.
inline std::filesystem::path writeHeaderAndData(std::string_view in, const char* singleName,
                                                const char* detachedName) {
    std::string_view header, payload;
    if (!splitData(in, header, payload)) return writeFile(singleName, in);
    writeFile("data.raw", payload);
    return writeFile(detachedName, header);
}

}  // namespace splat::fuzz
