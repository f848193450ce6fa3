// Image files through OpenImageIO, written atomically (temporary file, then rename).
#include "splat/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>
#include <tuple>

#include "splat/atomic_file.h"
#include "splat/error.h"

namespace splat {

namespace fs = std::filesystem;

float srgbEncode(float x) {
    x = std::clamp(x, 0.0f, 1.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

std::pair<float, float> defaultWindow(const std::vector<const Image*>& images) {
    float lo = 0.0f, hi = -std::numeric_limits<float>::infinity();
    for (const Image* im : images)
        for (const glm::vec4& p : im->pixels)
            if (std::isfinite(p.r)) {
                lo = std::min(lo, p.r);
                hi = std::max(hi, p.r);
            }
    if (!(hi > lo)) hi = lo + 1.0f;
    return {lo, hi};
}

namespace {

std::vector<float> displayValues(const Image& image, const WriteOptions& o, int channels = 3) {
    std::vector<float> out(std::size_t(image.width) * image.height * channels);
    const float span = o.windowHigh > o.windowLow ? o.windowHigh - o.windowLow : 1.0f;
    for (std::size_t n = 0; n < image.pixels.size(); ++n) {
        glm::vec4 c = image.pixels[n];
        // With alpha, colour is stored un-premultiplied (PNG convention).
        if (channels == 4 && o.mapping == DisplayMapping::Srgb && c.a > 0.0f && c.a < 1.0f)
            c = glm::vec4(glm::vec3(c) / c.a, c.a);
        for (int ch = 0; ch < 3; ++ch) {
            float v;
            if (o.mapping == DisplayMapping::Window)
                v = std::clamp((c.r - o.windowLow) / span, 0.0f, 1.0f);
            else if (o.mapping == DisplayMapping::Display)
                v = std::clamp(std::isfinite(c[ch]) ? c[ch] : 0.0f, 0.0f, 1.0f);
            else
                v = srgbEncode(std::isfinite(c[ch]) ? c[ch] : 0.0f);
            out[n * channels + ch] = v;
        }
        if (channels == 4)
            out[n * channels + 3] = std::clamp(std::isfinite(c.a) ? c.a : 0.0f, 0.0f, 1.0f);
    }
    return out;
}

// Metadata as attributes; TIFF keeps only its own tags, so there the entries are also
// lines "key: value" of the ImageDescription tag.
void addMetadata(OIIO::ImageSpec& spec, const WriteOptions& o, bool tiff) {
    std::string description;
    for (const auto& [key, value] : o.metadata) {
        spec.attribute(key, value);
        if (tiff && key != "Software" && !value.empty()) description += key + ": " + value + "\n";
    }
    if (!description.empty()) spec.attribute("ImageDescription", description);
}

}  // namespace

void checkImagePath(const std::string& path) {
    const std::string ext = lowerExtension(path);
    if (ext != ".exr" && ext != ".tif" && ext != ".tiff" && ext != ".png" && ext != ".gif" &&
        ext != ".jpg" && ext != ".jpeg")
        throw Error(path + ": unsupported image type '" + ext + "' (use .png, .exr or .tif)");
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty() && !fs::is_directory(parent))
        throw Error(path + ": folder '" + parent.string() + "' does not exist");
    if (fs::is_directory(path)) throw Error(path + ": is a folder, not an image file name");
}

namespace {
/// Encodes one image with OpenImageIO into memory (an IOVecOutput proxy): the encoder's
/// errors are its own, and the bytes then reach the disk through AtomicFile's checked
/// writes, so a full disk can never be mistaken for a written file.
std::vector<unsigned char> encodeToMemory(const std::string& ext, OIIO::ImageSpec spec,
                                          const void* pixels) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    const std::string name = "memory" + ext;
    auto out = OIIO::ImageOutput::create(name);
    if (!out) throw Error("cannot create an image writer for '" + ext + "'");
    if (!out->supports("ioproxy"))
        throw Error("this OpenImageIO cannot encode '" + ext + "' in memory");
    void* ptr = &proxy;
    spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &ptr);
    bool ok = out->open(name, spec) && out->write_image(OIIO::TypeDesc::FLOAT, pixels);
    std::string err = out->geterror();
    ok = out->close() && ok;
    if (err.empty()) err = out->geterror();
    if (!ok || bytes.empty())
        throw Error("cannot encode image (" + (err.empty() ? "encoder failed" : err) + ")");
    return bytes;
}
}  // namespace

void writeImage(const std::string& path, const Image& image, const WriteOptions& options) {
    checkImagePath(path);
    const std::string ext = lowerExtension(path);
    const bool isFloat = ext == ".exr" || ext == ".tif" || ext == ".tiff";
    if (image.width < 1 || image.height < 1) throw Error(path + ": image is empty");

    std::vector<unsigned char> bytes;
    try {
        if (isFloat) {
            OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::FLOAT);
            spec.channelnames = {"R", "G", "B", "A"};
            spec.alpha_channel = 3;
            addMetadata(spec, options, ext != ".exr");
            bytes = encodeToMemory(ext, spec, image.pixels.data());
        } else {
            const bool png = ext == ".png";
            if (options.bitDepth != 8 && !(png && options.bitDepth == 16))
                throw Error("bit depth " + std::to_string(options.bitDepth) +
                            " is not supported (8, or 16 for .png)");
            const int channels = png && options.alpha ? 4 : 3;
            const std::vector<float> v = displayValues(image, options, channels);
            OIIO::ImageSpec spec(
                image.width, image.height, channels,
                options.bitDepth == 16 ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8);
            if (channels == 4) spec.alpha_channel = 3;
            addMetadata(spec, options, false);
            bytes = encodeToMemory(ext, spec, v.data());
        }
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
    writeFileAtomic(path, bytes.data(), bytes.size());
}

std::vector<unsigned char> encodeImage(const Image& image, const std::string& ext,
                                       const WriteOptions& options) {
    const std::string e = lowerExtension("x" + ext);
    if (e != ".png" && e != ".gif" && e != ".jpg" && e != ".jpeg")
        throw Error("cannot encode an image as '" + ext + "' (use .png, .gif or .jpg)");
    if (image.width < 1 || image.height < 1) throw Error("cannot encode an empty image");
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    const std::string name = "memory" + e;
    auto out = OIIO::ImageOutput::create(name);
    if (!out || !out->supports("ioproxy"))
        throw Error("this OpenImageIO cannot encode '" + e + "' in memory");
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
    void* ptr = &proxy;
    spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &ptr);
    const std::vector<float> v = displayValues(image, options);
    bool ok = out->open(name, spec) && out->write_image(OIIO::TypeDesc::FLOAT, v.data());
    const std::string err = out->geterror();
    ok = out->close() && ok;
    if (!ok) throw Error("cannot encode image (" + (err.empty() ? "write failed" : err) + ")");
    return bytes;
}

std::vector<unsigned char> encodeAnimatedGif(const std::vector<Image>& frames,
                                             const WriteOptions& options, int fps) {
    if (frames.empty()) throw Error("no frames to write");
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput proxy(bytes);
    const std::string name = "memory.gif";
    auto out = OIIO::ImageOutput::create(name);
    if (!out || !out->supports("multiimage") || !out->supports("ioproxy"))
        throw Error("this OpenImageIO cannot write animated GIFs");
    OIIO::ImageSpec spec(frames[0].width, frames[0].height, 3, OIIO::TypeDesc::UINT8);
    void* ptr = &proxy;
    spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &ptr);
    const int rate[2] = {std::max(fps, 1), 1};
    spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
    spec.attribute("oiio:Movie", 1);
    spec.attribute("oiio:LoopCount", 0);
    std::vector<OIIO::ImageSpec> specs(frames.size(), spec);
    bool ok = out->open(name, int(specs.size()), specs.data());
    for (std::size_t f = 0; ok && f < frames.size(); ++f) {
        if (frames[f].width != spec.width || frames[f].height != spec.height) {
            ok = false;
            break;
        }
        if (f > 0) ok = out->open(name, spec, OIIO::ImageOutput::AppendSubimage);
        const std::vector<float> v = displayValues(frames[f], options);
        ok = ok && out->write_image(OIIO::TypeDesc::FLOAT, v.data());
    }
    const std::string err = out->geterror();
    ok = out->close() && ok;
    if (!ok)
        throw Error("cannot write the animation (" + (err.empty() ? "write failed" : err) + ")");
    return bytes;
}

void writeAnimatedGif(const std::string& path, const std::vector<Image>& frames,
                      const WriteOptions& options, int fps) {
    checkImagePath(path);
    if (lowerExtension(path) != ".gif") throw Error(path + ": an animation must be a .gif file");
    if (frames.empty()) throw Error(path + ": no frames to write");
    std::vector<unsigned char> bytes;
    try {
        bytes = encodeAnimatedGif(frames, options, fps);
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
    writeFileAtomic(path, bytes.data(), bytes.size());
}

Image readImage(const std::string& path) {
    if (!fs::exists(path)) throw Error(path + ": file not found");
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": cannot read image (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    const int nc = spec.nchannels;
    std::vector<float> buf(std::size_t(spec.width) * spec.height * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, buf.data()))
        throw Error(path + ": cannot read image (" + in->geterror() + ")");
    Image img(spec.width, spec.height);
    for (std::size_t n = 0; n < img.pixels.size(); ++n) {
        glm::vec4 c(0.0f, 0.0f, 0.0f, 1.0f);
        for (int ch = 0; ch < std::min(nc, 4); ++ch) c[ch] = buf[n * nc + ch];
        if (nc < 3) c.g = c.b = c.r;
        if (nc == 2) c.a = buf[n * nc + 1];
        img.pixels[n] = c;
    }
    return img;
}

Image toDisplay(const Image& image, const WriteOptions& options) {
    const std::vector<float> v = displayValues(image, options);
    Image out(image.width, image.height);
    for (std::size_t n = 0; n < out.pixels.size(); ++n)
        out.pixels[n] = glm::vec4(v[n * 3], v[n * 3 + 1], v[n * 3 + 2], 1.0f);
    return out;
}

Image downscale(const Image& im, int maxSide) {
    const int longest = std::max(im.width, im.height);
    const int f = std::max(1, (longest + std::max(maxSide, 1) - 1) / std::max(maxSide, 1));
    if (f == 1) return im;
    Image out(std::max(1, im.width / f), std::max(1, im.height / f));
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            glm::vec4 sum(0.0f);
            int count = 0;
            for (int v = 0; v < f; ++v)
                for (int u = 0; u < f; ++u)
                    if (x * f + u < im.width && y * f + v < im.height) {
                        sum += im.at(x * f + u, y * f + v);
                        ++count;
                    }
            out.at(x, y) = sum / float(count);
        }
    return out;
}

Image contactSheet(const std::vector<Image>& frames, int columns) {
    if (frames.empty()) return Image();
    const int n = int(frames.size());
    const int cols = columns > 0 ? columns : int(std::ceil(std::sqrt(double(n))));
    const int rows = (n + cols - 1) / cols;
    const int w = frames[0].width, h = frames[0].height;
    Image sheet(cols * w, rows * h, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    for (int f = 0; f < n; ++f) {
        const int ox = (f % cols) * w, oy = (f / cols) * h;
        for (int y = 0; y < std::min(h, frames[f].height); ++y)
            for (int x = 0; x < std::min(w, frames[f].width); ++x)
                sheet.at(ox + x, oy + y) = frames[f].at(x, y);
    }
    return sheet;
}

}  // namespace splat
