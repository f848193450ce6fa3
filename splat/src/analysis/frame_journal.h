#pragma once
// A journal of rendered frames for resuming an interrupted analysis: each frame
// is one file written atomically (splat/atomic_file.h) holding its pixels bit for bit, the
// stats the analysis uses, and an FNV-1a 64 checksum; a frame is read back only when its
// size and checksum match, so a resumed analysis measures exactly the images of an
// uninterrupted one.
#include <filesystem>

#include "splat/image.h"
#include "splat/settings.h"

namespace splat::journal {

/// Writes `image` and its stats (milliseconds, sheet axis and sign) to `file`.
void storeFrame(const std::filesystem::path& file, const Image& image, const RenderStats& stats);

/// Reads a frame of `width` x `height` back; false (and nothing changed) when the file is
/// missing, of another size, or fails its checksum.
bool loadFrame(const std::filesystem::path& file, int width, int height, Image& image,
               RenderStats& stats);

/// True when `file` exists with the size of a `width` x `height` frame (cheap; loadFrame
/// still checks the checksum).
bool hasFrame(const std::filesystem::path& file, int width, int height);

}  // namespace splat::journal
