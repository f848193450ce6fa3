#pragma once
// Atomic file output: every file splat writes (images, volumes, reports, JSON) is written
// under a hidden temporary name in the destination folder and renamed over the target
// only when complete, so an interrupted or failed write never leaves a half-written file.
#include <filesystem>
#include <string>
#include <string_view>

namespace splat {

/// A temporary sibling of `target` that becomes `target` on commit(). The temporary keeps
/// the target's extension (writers such as OpenImageIO pick the format by it). Destroyed
/// without commit(), it removes the temporary.
class AtomicFile {
  public:
    explicit AtomicFile(const std::filesystem::path& target);
    ~AtomicFile();
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    /// Where to write the contents.
    const std::filesystem::path& temporary() const { return tmp_; }
    const std::filesystem::path& target() const { return target_; }
    /// Renames the temporary over the target. Throws splat::Error naming the target.
    void commit();

  private:
    std::filesystem::path target_, tmp_;
    bool committed_ = false;
};

/// Writes `bytes` to `path` atomically. Refuses to write through a folder or over a
/// folder; throws splat::Error naming the file.
void writeFileAtomic(const std::filesystem::path& path, const void* bytes, std::size_t size);
void writeTextAtomic(const std::filesystem::path& path, std::string_view text);

/// Lower-case extension of a file name, including the double ones splat knows
/// (".nii.gz", ".raw.gz"); "" when there is none.
std::string lowerExtension(const std::filesystem::path& path);

}  // namespace splat
