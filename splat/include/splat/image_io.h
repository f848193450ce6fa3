#pragma once
// Image files through OpenImageIO. Writes are atomic: a temporary file in the same folder,
// renamed over the target only when complete.
#include <string>
#include <utility>
#include <vector>

#include "splat/image.h"

namespace splat {

/// How float values become display values in 8-bit files (.png, .gif).
enum class DisplayMapping {
    Srgb,     ///< colour in [0, 1], sRGB-encoded (dvr, iso)
    Window,   ///< grey, linear map of [windowLow, windowHigh] of the red channel to [0, 1]
    Display,  ///< the values are display values already (e.g. read back from a PNG)
};

struct WriteOptions {
    DisplayMapping mapping = DisplayMapping::Srgb;
    float windowLow = 0.0f, windowHigh = 1.0f;
    /// .png: 8 or 16 bits per channel.
    int bitDepth = 8;
    /// .png: an alpha channel (the image's alpha; a transparent background stays
    /// transparent). Colour is written un-premultiplied, as PNG expects.
    bool alpha = false;
    /// Key/value text stored in the file (PNG text chunks, EXR and TIFF attributes), e.g.
    /// {"Software", "splat 0.1.0"}, {"splat:scene", "{...}"}; read back with OpenImageIO's
    /// ImageSpec::get_string_attribute(key).
    std::vector<std::pair<std::string, std::string>> metadata;
};

/// The default display window of mip and x-ray images: [min(0, lowest), highest] of the red
/// channel over `images` (finite values; high = low + 1 when flat). Data below 0 (CT in HU,
/// where a mip ray that misses the bone sees air at -1000) keep their range; data at or
/// above 0 keep the window [0, max].
std::pair<float, float> defaultWindow(const std::vector<const Image*>& images);

/// Writes `.png`, `.gif`, `.jpg` (8-bit display values, RGB) or `.exr`, `.tif`/`.tiff`
/// (32-bit float RGBA, values as computed). Throws splat::Error naming the file on failure.
void writeImage(const std::string& path, const Image& image, const WriteOptions& options = {});

/// Checks before a long render that `path` can be written: a supported extension and an
/// existing folder. Throws splat::Error naming the file otherwise.
void checkImagePath(const std::string& path);

/// Writes frames (all the same size) as a looping animated GIF, `fps` frames per second.
void writeAnimatedGif(const std::string& path, const std::vector<Image>& frames,
                      const WriteOptions& options, int fps = 12);

/// The bytes of an 8-bit image file (`ext`: ".png", ".gif" or ".jpg") encoded in memory,
/// display values as writeImage makes them. Throws splat::Error on failure.
std::vector<unsigned char> encodeImage(const Image& image, const std::string& ext,
                                       const WriteOptions& options = {});
/// The bytes of the looping animated GIF writeAnimatedGif writes, encoded in memory.
std::vector<unsigned char> encodeAnimatedGif(const std::vector<Image>& frames,
                                             const WriteOptions& options, int fps = 12);

/// Reads any image OpenImageIO can read as float RGBA (missing alpha becomes 1).
Image readImage(const std::string& path);

/// Encodes a linear value in [0, 1] with the sRGB transfer curve.
float srgbEncode(float linear);

/// The display values (RGB in [0, 1], alpha 1) an 8-bit file would hold for `image`.
Image toDisplay(const Image& image, const WriteOptions& options);

/// A box-filtered copy whose longest side is at most `maxSide` pixels (an integer factor).
Image downscale(const Image& image, int maxSide);

/// Frames (any sizes up to the first's) tiled left to right, top to bottom, `columns` per
/// row (0: about square), on black.
Image contactSheet(const std::vector<Image>& frames, int columns = 0);

}  // namespace splat
