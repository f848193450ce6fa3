#include <filesystem>
#include "splat/atomic_file.h"
#include "splat/popping.h"
namespace splat {
void writePoppingReport(const PoppingResult& r, const std::string& dir, const std::string& cl) {
    std::filesystem::create_directories(dir);
    writeTextAtomic(std::filesystem::path(dir) / "summary.json", "{\"cmd\": \"" + cl + "\", \"views\": " + std::to_string(r.angles.size()) + "}\n");
}
}
