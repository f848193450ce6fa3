// libFuzzer target: headerless raw "by name". The first line of the input is the file
// name's middle (e.g. "4x3x2_int16", so the file is "v_4x3x2_int16.raw"), optionally
// followed by " gz" (the rest is written as .raw.gz, already compressed or not) and
// " skip=N" (RawOptions::headerBytes); the rest is the file.
#include <cstdlib>

#include "fuzz_util.h"
#include "splat/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view in(reinterpret_cast<const char*>(data), size);
    const std::size_t eol = in.find('\n');
    if (eol == std::string_view::npos || eol > 200) return 0;
    std::string line(in.substr(0, eol));
    std::string_view body = in.substr(eol + 1);
    splat::LoadOptions options;
    bool gz = false;
    if (const std::size_t s = line.find(" skip="); s != std::string::npos) {
        options.raw.headerBytes = std::strtoull(line.c_str() + s + 6, nullptr, 10);
        line.resize(s);
    }
    if (line.size() >= 3 && line.compare(line.size() - 3, 3, " gz") == 0) {
        gz = true;
        line.resize(line.size() - 3);
    }
    for (char c : line)  // names only: no folders
        if (c == '/' || c == '\0') return 0;
    const auto p = splat::fuzz::writeFile("v_" + line + (gz ? ".raw.gz" : ".raw"), body);
    splat::fuzz::expectOnlySplatErrors([&] { splat::loadVolume(p.string(), options); });
    std::filesystem::remove(p);
    return 0;
}
