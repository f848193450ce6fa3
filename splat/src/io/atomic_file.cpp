// Atomic file output (see splat/atomic_file.h): temporary sibling, checked write(2)
// calls, fsync, checked close, rename, fsync of the folder.
#include "splat/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <regex>

#include "splat/error.h"

namespace fs = std::filesystem;

namespace splat {

namespace {
// Unique within the process (counter) and across processes (pid): a temporary whose pid
// no longer runs belongs to a killed process (removeStaleTemporaries).
std::string uniqueTag() {
    static std::atomic<unsigned> counter{0};
    return std::to_string(long(::getpid())) + "-" + std::to_string(counter++);
}

std::string osError(int error) { return std::strerror(error); }

/// fsync of a folder, so that a rename in it survives a crash; best effort (some file
/// systems refuse fsync on folders).
void syncFolder(const fs::path& dir) {
    const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return;
    (void)::fsync(fd);
    ::close(fd);
}

const std::regex& temporaryPattern() {
    static const std::regex re(R"(^\..+\.tmp([0-9]+)-[0-9]+(\..*)?$)");
    return re;
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
    if (fd_ >= 0) ::close(fd_);
    if (committed_) return;
    std::error_code ignored;
    fs::remove(tmp_, ignored);
}

void AtomicFile::fail(const std::string& what, int error) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    std::error_code ignored;
    fs::remove(tmp_, ignored);
    throw Error(target_.string() + ": " + what + " (" + osError(error) + ")");
}

void AtomicFile::write(const void* bytes, std::size_t size) {
    if (committed_ || synced_) throw Error(target_.string() + ": written after sync or commit");
    if (fd_ < 0) {
        fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
        if (fd_ < 0) fail("cannot create file", errno);
    }
    const char* p = static_cast<const char*>(bytes);
    while (size > 0) {
        const ssize_t n = ::write(fd_, p, size);
        if (n < 0 && errno == EINTR) continue;
        // write(2) returning 0 for a non-zero count is a full device in practice.
        if (n <= 0) fail("cannot write", n < 0 ? errno : ENOSPC);
        p += n;
        size -= std::size_t(n);
    }
}

void AtomicFile::sync() {
    if (committed_ || synced_) return;
    if (fd_ < 0) {
        // An external writer filled the temporary: it must be there and hold something.
        struct stat st {};
        if (::stat(tmp_.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
            std::error_code ignored;
            fs::remove(tmp_, ignored);
            throw Error(target_.string() + ": write failed (nothing was written)");
        }
        if (st.st_size == 0) {
            std::error_code ignored;
            fs::remove(tmp_, ignored);
            throw Error(target_.string() + ": write failed (the writer produced an empty file)");
        }
        fd_ = ::open(tmp_.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd_ < 0) fail("cannot write", errno);
    }
    // Delayed write errors (ENOSPC, EIO on network and some local file systems) surface here.
    if (::fsync(fd_) != 0 && errno != EINVAL) fail("cannot write", errno);
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0 && errno != EINTR) {
        const int e = errno;
        std::error_code ignored;
        fs::remove(tmp_, ignored);
        throw Error(target_.string() + ": cannot write (" + osError(e) + ")");
    }
    synced_ = true;
}

void AtomicFile::commit() {
    if (committed_) return;
    sync();
    if (::rename(tmp_.c_str(), target_.c_str()) != 0) fail("cannot write", errno);
    committed_ = true;
    syncFolder(target_.parent_path());
}

void writeFileAtomic(const fs::path& path, const void* bytes, std::size_t size) {
    AtomicFile file(path);
    file.write(bytes, size);
    file.commit();
}

void writeTextAtomic(const fs::path& path, std::string_view text) {
    writeFileAtomic(path, text.data(), text.size());
}

bool isAtomicTemporary(const std::string& fileName) {
    return std::regex_match(fileName, temporaryPattern());
}

std::size_t removeStaleTemporaries(const fs::path& dir) {
    std::size_t removed = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir.empty() ? fs::path(".") : dir, ec)) {
        const std::string name = e.path().filename().string();
        std::smatch m;
        if (!std::regex_match(name, m, temporaryPattern())) continue;
        long pid = 0;
        try {
            pid = std::stol(m[1].str());
        } catch (const std::exception&) {
            continue;
        }
        if (pid <= 0 || pid == long(::getpid())) continue;
        if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // still running
        std::error_code ignored;
        removed += fs::remove(e.path(), ignored) ? 1 : 0;
    }
    return removed;
}

}  // namespace splat
