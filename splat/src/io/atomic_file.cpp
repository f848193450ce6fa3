// Atomic file output (see splat/atomic_file.h).
#include "splat/atomic_file.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <fstream>
#include <random>

#include "splat/error.h"

namespace fs = std::filesystem;

namespace splat {

namespace {
// Unique within the process (counter) and across processes (random seed).
std::string uniqueTag() {
    static std::atomic<unsigned> counter{0};
    static const unsigned seed = std::random_device{}();
    return std::to_string(seed % 1000000u) + "-" + std::to_string(counter++);
}
}  // namespace

std::string lowerExtension(const fs::path& path) {
    std::string name = path.filename().string();
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* twice : {".nii.gz", ".raw.gz"}) {
        const std::string t(twice);
        if (name.size() > t.size() && name.compare(name.size() - t.size(), t.size(), t) == 0)
            return t;
    }
    const std::size_t dot = name.rfind('.');
    return dot == std::string::npos || dot == 0 ? std::string() : name.substr(dot);
}

AtomicFile::AtomicFile(const fs::path& target) : target_(target) {
    std::error_code ec;
    if (fs::is_directory(target_, ec))
        throw Error(target_.string() + ": is a folder, not a file name");
    const fs::path dir = target_.parent_path();
    if (!dir.empty() && !fs::is_directory(dir, ec))
        throw Error(target_.string() + ": folder '" + dir.string() + "' does not exist");
    const std::string ext = lowerExtension(target_);
    const std::string file = target_.filename().string();
    const std::size_t stem = file.size() - ext.size();
    std::string name(1, '.');
    name.append(file, 0, stem).append(".tmp").append(uniqueTag()).append(file, stem);
    tmp_ = (dir.empty() ? fs::path(".") : dir) / name;
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    std::error_code ignored;
    fs::remove(tmp_, ignored);
}

void AtomicFile::commit() {
    std::error_code ec;
    if (!fs::is_regular_file(tmp_, ec))
        throw Error(target_.string() + ": write failed (nothing was written)");
    fs::rename(tmp_, target_, ec);
    if (ec) throw Error(target_.string() + ": cannot write file (" + ec.message() + ")");
    committed_ = true;
}

void writeFileAtomic(const fs::path& path, const void* bytes, std::size_t size) {
    AtomicFile file(path);
    {
        std::ofstream out(file.temporary(), std::ios::binary | std::ios::trunc);
        if (!out) throw Error(path.string() + ": cannot create file");
        out.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(size));
        out.close();
        if (!out) throw Error(path.string() + ": write failed");
    }
    file.commit();
}

void writeTextAtomic(const fs::path& path, std::string_view text) {
    writeFileAtomic(path, text.data(), text.size());
}

}  // namespace splat
