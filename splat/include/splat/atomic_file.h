#pragma once
// Atomic file output: every file splat writes (images, volumes, meshes, reports, JSON,
// manifests) is written under a hidden temporary name in the destination folder, checked,
// flushed to the disk (fsync) and renamed over the target only when complete, so a failed
// or interrupted write never leaves an empty or half-written file, and a previous file of
// that name stays untouched until the new one is whole.
//
// Two ways to fill the temporary:
//  - write(): splat's own bytes, every write(2) checked (a full disk, an I/O error or a
//    file size limit is reported with the OS error);
//  - an external writer (a library or a program such as ffmpeg) writes temporary() itself;
//    commit() then refuses a temporary that is missing or empty, and fsyncs it.
// Errors are splat::Error with one line "FILE: cannot write (OS error)".
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace splat {

/// A temporary sibling of `target` that becomes `target` on commit(). The temporary keeps
/// the target's extension (writers such as OpenImageIO pick the format by it) and is named
/// ".NAME.tmp<pid>-<n>.EXT". Destroyed without commit(), it removes the temporary.
class AtomicFile {
  public:
    explicit AtomicFile(const std::filesystem::path& target);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    /// Where an external writer writes the contents.
    const std::filesystem::path& temporary() const { return tmp_; }
    const std::filesystem::path& target() const { return target_; }
    /// Appends `size` bytes to the temporary (created on the first call). Throws
    /// splat::Error naming the target and the OS error; the temporary is then removed.
    void write(const void* bytes, std::size_t size);
    /// Flushes the temporary to the disk (fsync) and closes it, errors checked; commit()
    /// does it when not done. Call it on each of a set of files before committing any,
    /// so that a failure leaves every previous file of the set untouched.
    void sync();
    /// sync(), then renames the temporary over the target and fsyncs the folder. Throws
    /// splat::Error naming the target (the previous target, if any, is untouched and the
    /// temporary removed).
    void commit();

  private:
    [[noreturn]] void fail(const std::string& what, int error);
    std::filesystem::path target_, tmp_;
    int fd_ = -1;
    bool synced_ = false, committed_ = false;
};

/// Writes `bytes` to `path` atomically. Refuses to write through a folder or over a
/// folder; throws splat::Error naming the file and the OS error.
void writeFileAtomic(const std::filesystem::path& path, const void* bytes, std::size_t size);
void writeTextAtomic(const std::filesystem::path& path, std::string_view text);

/// Removes the temporaries AtomicFile left in `dir` when its process was killed (a
/// temporary whose process no longer runs). Returns how many were removed.
std::size_t removeStaleTemporaries(const std::filesystem::path& dir);

/// True for a name AtomicFile gives its temporaries (".NAME.tmp<pid>-<n>[.EXT]").
bool isAtomicTemporary(const std::string& fileName);

/// Lower-case extension of a file name, including the double ones splat knows
/// (".nii.gz", ".raw.gz"); "" when there is none.
std::string lowerExtension(const std::filesystem::path& path);

}  // namespace splat
