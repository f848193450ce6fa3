// OME-Zarr images and bare Zarr v2 arrays (splat/sparse_files.h), on files written by
// python3-zarr (tests/sparse/make_sparse_data.py): every dtype, byte order and compressor
// reads the same integer ramp exactly; an OME-Zarr image equals the NIfTI nibabel wrote
// of the same samples (samples, spacing, origin, background from fill_value); levels, time
// points and channels select the right block; bricks read alone equal crops; bad files give
// one line.
#include <zlib.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "sparse_util.h"
#include "splat/bricks.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/sparse_files.h"
#include "splat/volume_io.h"

using namespace splat;
using namespace splat::test;
namespace fs = std::filesystem;

namespace {

float ramp(int i, int j, int k) { return float((i + 2 * j + 3 * k) % 97); }

void requireSameSamples(const Volume& a, const Volume& b) {
    REQUIRE(a.dims == b.dims);
    std::size_t differ = 0;
    for (std::size_t n = 0; n < a.voxelCount(); ++n) differ += a.value(n) != b.value(n);
    CHECK(differ == 0);
}

void writeText(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

/// The message of the splat::Error that loading `spec` throws ("" when it loads).
std::string loadError(const std::string& spec, const LoadOptions& options = {}) {
    try {
        loadVolume(spec, options);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

/// A copy of `from` (a folder) at `to`, replaced.
fs::path copyFolder(const fs::path& from, const fs::path& to) {
    fs::remove_all(to);
    fs::copy(from, to, fs::copy_options::recursive);
    return to;
}

std::string replaced(std::string s, const std::string& a, const std::string& b) {
    const std::size_t at = s.find(a);
    REQUIRE(at != std::string::npos);
    return s.replace(at, a.size(), b);
}

}  // namespace

TEST_CASE("zarr: every dtype, byte order and compressor reads the ramp exactly", "[zarr]") {
    SPARSE_DATA_OR_SKIP(data);
    int files = 0;
    for (const auto& e : fs::directory_iterator(data / "dtypes")) {
        INFO(e.path().filename().string());
        const Volume v = loadVolume(e.path().string());
        REQUIRE(v.dims == glm::ivec3(13, 11, 9));
        CHECK(v.spacing == glm::dvec3(1.0));
        CHECK(v.origin == glm::dvec3(0.0));
        std::size_t wrong = 0;
        for (int k = 0; k < 9; ++k)
            for (int j = 0; j < 11; ++j)
                for (int i = 0; i < 13; ++i) wrong += v.at(i, j, k) != ramp(i, j, k);
        CHECK(wrong == 0);
        // Every chunk stored: b follows loadVolume's rule, not the fill_value.
        CHECK(v.backgroundSource == "median of the outer faces");
        ++files;
    }
    CHECK(files == 14 * 4 + 2);
}

TEST_CASE("zarr: an OME-Zarr image equals the NIfTI of the same samples", "[zarr]") {
    SPARSE_DATA_OR_SKIP(data);
    const Volume nii = loadVolume((data / "same.nii.gz").string());
    const Volume z = loadVolume((data / "same.zarr").string());
    requireSameSamples(nii, z);
    // Spacing and origin exact in the float32 of NIfTI too.
    CHECK(z.spacing == nii.spacing);
    CHECK(z.origin == nii.origin);
    CHECK(z.spacing == glm::dvec3(0.75, 1.125, 1.25));
    CHECK(z.origin == glm::dvec3(2.0, -3.0, 5.0));
    // Chunks holding only the background are not stored: b is the fill_value, 3, which is
    // also the NIfTI's median of the outer faces.
    CHECK(z.background == 3.0f);
    CHECK(z.backgroundSource.find("fill_value") != std::string::npos);
    CHECK(nii.background == 3.0f);
    CHECK(z.source.find("OME-Zarr <f4 level 0 of 2") != std::string::npos);

    LoadOptions coarse;
    coarse.level = 1;
    const Volume z1 = loadVolume((data / "same.zarr").string(), coarse);
    REQUIRE(z1.dims == glm::ivec3(10, 9, 7));
    CHECK(z1.spacing == glm::dvec3(1.5, 2.25, 2.5));
    CHECK(z1.origin == z.origin);
    std::size_t wrong = 0;
    for (int k = 0; k < z1.dims.z; ++k)
        for (int j = 0; j < z1.dims.y; ++j)
            for (int i = 0; i < z1.dims.x; ++i)
                wrong += z1.at(i, j, k) != nii.at(2 * i, 2 * j, 2 * k);
    CHECK(wrong == 0);

    const ZarrImageInfo info = describeZarr((data / "same.zarr").string());
    CHECK(info.axes == "zyx");
    REQUIRE(info.levels.size() == 2);
    CHECK(info.levels[0].compressor == "blosc");
    CHECK(info.levels[1].compressor == "zlib");
    CHECK(info.levels[1].dims == glm::ivec3(10, 9, 7));
    CHECK(isZarrFolder((data / "same.zarr").string()));
    CHECK_FALSE(isZarrFolder((data / "same.nii.gz").string()));

    coarse.level = 2;
    CHECK(loadError((data / "same.zarr").string(), coarse).find("level 2 is out of range") !=
          std::string::npos);
}

TEST_CASE("zarr: time points and channels of a 5D image", "[zarr]") {
    SPARSE_DATA_OR_SKIP(data);
    const std::string spec = (data / "tczyx.zarr").string();
    for (int t = 0; t < 2; ++t)
        for (int c = 0; c < 3; ++c) {
            INFO("t " << t << " c " << c);
            LoadOptions o;
            o.time = t;
            o.channel = c;
            const Volume v = loadVolume(spec, o);
            REQUIRE(v.dims == glm::ivec3(13, 11, 9));
            CHECK(v.spacing == glm::dvec3(0.5, 1.5, 2.0));
            CHECK(v.origin == glm::dvec3(30.0, 20.0, 10.0));
            CHECK(v.note.empty());
            std::size_t wrong = 0;
            for (int k = 0; k < 9; ++k)
                for (int j = 0; j < 11; ++j)
                    for (int i = 0; i < 13; ++i)
                        wrong += v.at(i, j, k) != 1000.0f * t + 100.0f * c + ramp(i, j, k);
            CHECK(wrong == 0);
        }
    const Volume first = loadVolume(spec);
    CHECK(first.at(1, 0, 0) == 1.0f);
    CHECK(first.note.find("2 time points: loaded time point 0") != std::string::npos);
    CHECK(first.note.find("3 channels: loaded channel 0") != std::string::npos);
    LoadOptions o;
    o.channel = 3;
    CHECK(loadError(spec, o).find("channel 3 is out of range (3 channels: 0..2)") !=
          std::string::npos);
    const ZarrImageInfo info = describeZarr(spec);
    CHECK(info.axes == "tczyx");
    CHECK(info.times == 2);
    CHECK(info.channels == 3);
}

TEST_CASE("zarr: bricks read alone equal crops of the whole volume", "[zarr][bricks]") {
    SPARSE_DATA_OR_SKIP(data);
    for (const std::string name : {"same.zarr", "dtypes/u2_be_blosc.zarr", "tczyx.zarr"}) {
        INFO(name);
        const std::string spec = (data / name).string();
        LoadOptions o;
        if (name == "tczyx.zarr") {
            o.time = 1;
            o.channel = 2;
        }
        checkBrickReadAlone(spec, o, glm::ivec3(2, 3, 1), glm::ivec3(1, 2, 3));
    }
}

TEST_CASE("zarr: bad files give one line", "[zarr][errors]") {
    SPARSE_DATA_OR_SKIP(data);
    const fs::path tmp = testTmpDir("zarr_bad");
    const fs::path good = data / "dtypes" / "u2_le_none.zarr";
    const std::string meta = readTextFile(good / ".zarray");
    const auto withMeta = [&](const std::string& name, const std::string& text) {
        const fs::path d = copyFolder(good, tmp / name);
        writeText(d / ".zarray", text);
        return loadError(d.string());
    };
    struct Case {
        std::string name, from, to, expect;
    };
    const std::vector<Case> cases = {
        {"complex.zarr", "\"<u2\"", "\"<c8\"", "complex samples"},
        {"unknown.zarr", "\"<u2\"", "\"<q3\"", "dtype '<q3' is not supported"},
        {"float16.zarr", "\"<u2\"", "\"<f2\"", "dtype '<f2' is not supported"},
        {"structured.zarr", "\"<u2\"", "[[\"a\", \"<u2\"]]", "structured dtype"},
        {"lz4.zarr", "\"compressor\": null", "\"compressor\": {\"id\": \"lz4\"}",
         "compressor 'lz4' is not supported"},
        {"filters.zarr", "\"filters\": null", "\"filters\": [{\"id\": \"delta\"}]", "filters"},
        {"huge.zarr", "\"chunks\": [\n        3,", "\"chunks\": [\n        300000000,",
         "larger than splat reads"},
        {"v3.zarr", "\"zarr_format\": 2", "\"zarr_format\": 3", "zarr_format is not 2"},
    };
    for (const Case& c : cases) {
        INFO(c.name);
        const std::string e = withMeta(c.name, replaced(meta, c.from, c.to));
        CHECK(e.find(c.expect) != std::string::npos);
        CHECK(e.find('\n') == std::string::npos);
    }
    {
        INFO("not JSON");
        CHECK(withMeta("json.zarr", "{\"zarr_format\": 2,").find("not valid JSON") !=
              std::string::npos);
    }
    {
        INFO("a truncated uncompressed chunk");
        const fs::path d = copyFolder(good, tmp / "short.zarr");
        fs::resize_file(d / "0.0.0", 17);
        const std::string e = loadError(d.string());
        CHECK(e.find("0.0.0: uncompressed chunk holds 17 bytes, expected 120") !=
              std::string::npos);
    }
    {
        INFO("a zlib chunk that decompresses to the wrong size");
        const fs::path d = copyFolder(data / "dtypes" / "u2_le_zlib.zarr", tmp / "zsize.zarr");
        std::vector<unsigned char> raw(100, 7), packed(256);
        uLongf size = packed.size();
        REQUIRE(compress(packed.data(), &size, raw.data(), raw.size()) == Z_OK);
        std::ofstream(d / "1.1.1", std::ios::binary)
            .write(reinterpret_cast<const char*>(packed.data()), std::streamsize(size));
        const std::string e = loadError(d.string());
        CHECK(e.find("1.1.1: chunk decompresses to 100 bytes, expected 120") != std::string::npos);
    }
    {
        INFO("a corrupt blosc chunk");
        const fs::path d = copyFolder(data / "dtypes" / "u2_le_blosc.zarr", tmp / "blosc.zarr");
        writeText(d / "0.1.0", "not blosc at all");
        CHECK(loadError(d.string()).find("0.1.0: corrupt blosc data") != std::string::npos);
        fs::resize_file(d / "0.0.0", 20);
        writeText(d / "0.1.0", readTextFile(data / "dtypes" / "u2_le_blosc.zarr" / "0.1.0"));
        CHECK(loadError(d.string()).find("0.0.0: corrupt blosc data") != std::string::npos);
    }
    {
        INFO("levels that disagree");
        const fs::path d = copyFolder(data / "same.zarr", tmp / "levels.zarr");
        std::string attrs = readTextFile(d / ".zattrs");
        writeText(d / ".zattrs", replaced(attrs, "2.5,", "7.5,"));
        const std::string e = loadError(d.string());
        CHECK(e.find("level 1 ('1') spans") != std::string::npos);
        CHECK(e.find("(the levels disagree)") != std::string::npos);
        writeText(d / ".zattrs", replaced(attrs, "\"path\": \"1\"", "\"path\": \"../1\""));
        CHECK(loadError(d.string()).find("leaves the image's folder") != std::string::npos);
    }
    {
        INFO("a folder named .zarr that is none");
        const fs::path d = tmp / "empty.zarr";
        fs::create_directories(d);
        CHECK(loadError(d.string()).find("not an OME-Zarr image") != std::string::npos);
    }
}

TEST_CASE("zarr: splat info lists the levels; a bad image is one error line", "[zarr][cli]") {
    SPARSE_DATA_OR_SKIP(data);
    const RunResult r = runProgram(SPLAT_EXE, {"info", (data / "same.zarr").string()});
    CHECK(r.status == 0);
    CHECK(r.out.find("OME-Zarr:    axes zyx, 1 time point, 1 channel, 2 levels") !=
          std::string::npos);
    CHECK(r.out.find("level 1 '1': 10 x 9 x 7, spacing 1.5 x 2.25 x 2.5") != std::string::npos);
    const RunResult l =
        runProgram(SPLAT_EXE, {"info", (data / "same.zarr").string(), "--zarr-level", "1"});
    CHECK(l.status == 0);
    CHECK(l.out.find("10 x 9 x 7") != std::string::npos);
    const fs::path tmp = testTmpDir("zarr_cli");
    const fs::path bad = copyFolder(data / "dtypes" / "u1_le_none.zarr", tmp / "bad.zarr");
    fs::resize_file(bad / "1.0.2", 3);
    const RunResult e =
        runProgram(SPLAT_EXE, {"render", bad.string(), "-o", (tmp / "x.png").string()});
    CHECK(e.status == 1);
    REQUIRE(e.errLines().size() == 1);
    CHECK(e.errLines()[0].rfind("splat: error: ", 0) == 0);
    CHECK_FALSE(fs::exists(tmp / "x.png"));
}

TEST_CASE("zarr: the default level is the level of detail the view asks for", "[zarr][lod]") {
    SPARSE_DATA_OR_SKIP(data);
    const ZarrImageInfo info = describeZarr((data / "pyramid.zarr").string());
    REQUIRE(info.levels.size() == 3);
    // 32^3 voxels of 0.5: the bounding sphere's diameter, 27.7, fits the image, so a level-0
    // voxel covers 0.5 W / 27.7 pixels (1.155 at W = 64), a level-L one 2^L times as many.
    auto levelAt = [&](int size, const std::string& lod, RenderMode mode) {
        RenderSettings s;
        s.camera.width = s.camera.height = size;
        s.mode = mode;
        if (lod == "auto")
            s.quality.lod = LevelOfDetail::automatic();
        else if (lod == "brick")
            s.quality.lod = LevelOfDetail::perBrick();
        else
            s.quality.lod = LevelOfDetail::threshold(std::stod(lod));
        return zarrLevelForView(info, s);
    };
    // --lod 2: the first level whose voxel covers 2 pixels, else the coarsest.
    CHECK(levelAt(256, "2", RenderMode::Dvr) == 0);  // 4.6 pixels
    CHECK(levelAt(64, "2", RenderMode::Dvr) == 1);   // 1.155, 2.31
    CHECK(levelAt(32, "2", RenderMode::Dvr) == 2);   // 0.58, 1.155, 2.31
    CHECK(levelAt(16, "2", RenderMode::Dvr) == 2);   // the coarsest stored level
    // Off, and the reference ray caster (which always renders the full level): level 0.
    CHECK(levelAt(16, "0", RenderMode::Dvr) == 0);
    RenderSettings reference;
    reference.camera.width = reference.camera.height = 16;
    reference.quality.lod = LevelOfDetail::threshold(2);
    reference.renderer = RendererKind::Reference;
    CHECK(zarrLevelForView(info, reference) == 0);
    // --lod auto (xray): level 1 at v0 <= 0.472 pixels, level 2 at v0 <= 0.209.
    CHECK(levelAt(32, "auto", RenderMode::Xray) == 0);  // 0.58
    CHECK(levelAt(16, "auto", RenderMode::Xray) == 1);  // 0.29
    CHECK(levelAt(8, "auto", RenderMode::Xray) == 2);   // 0.14
    CHECK(levelAt(8, "auto", RenderMode::Dvr) == 0);    // auto applies to xray only
    CHECK(levelAt(8, "brick", RenderMode::Xray) == 0);  // bricks' levels come from level 0
}

TEST_CASE("zarr: a pyramid renders at its default level like the NIfTI of that level",
          "[zarr][lod][cli]") {
    SPARSE_DATA_OR_SKIP(data);
    const fs::path tmp = testTmpDir("zarr_lod");
    auto render = [&](const std::vector<std::string>& args, const std::string& name) {
        std::vector<std::string> all = {"render"};
        all.insert(all.end(), args.begin(), args.end());
        for (const std::string& a :
             std::vector<std::string>{"--mode", "mip", "--azimuth", "30", "--elevation", "20",
                                      "--threads", "2", "-o", (tmp / name).string()})
            all.push_back(a);
        const RunResult r = runProgram(SPLAT_EXE, all);
        INFO(r.err);
        REQUIRE(r.status == 0);
        return readImage((tmp / name).string());
    };
    auto same = [](const Image& a, const Image& b) {
        REQUIRE(a.width == b.width);
        REQUIRE(a.height == b.height);
        std::size_t differ = 0;
        for (std::size_t p = 0; p < a.pixels.size(); ++p) differ += a.pixels[p] != b.pixels[p];
        return differ == 0;
    };
    const std::string zarr = (data / "pyramid.zarr").string();
    for (const auto& [size, level] : {std::pair<std::string, int>{"64x64", 1}, {"32x32", 2}}) {
        INFO(size);
        const std::string nii = (data / ("pyramid_" + std::to_string(level) + ".nii.gz")).string();
        const Image z = render({zarr, "--lod", "2", "--size", size}, "z.exr");
        const Image n = render({nii, "--lod", "2", "--size", size}, "n.exr");
        CHECK(same(z, n));
        // Not a vacuous check: level 0 of the same file gives another image.
        const Image z0 =
            render({zarr, "--lod", "2", "--size", size, "--zarr-level", "0"}, "z0.exr");
        CHECK_FALSE(same(z, z0));
    }
    // rotate and bench choose the same way, and say which level they read.
    const RunResult rotate =
        runProgram(SPLAT_EXE, {"rotate", zarr, "--lod", "2", "--size", "32x32", "--frames", "1",
                               "-o", (tmp / "turn").string()});
    CHECK(rotate.status == 0);
    CHECK(rotate.out.find("reading OME-Zarr level 2 of 3") != std::string::npos);
    const RunResult bench =
        runProgram(SPLAT_EXE, {"bench", zarr, "--lod", "2", "--size", "64x64", "--repeats", "1"});
    CHECK(bench.status == 0);
    CHECK(bench.out.find("reading OME-Zarr level 1 of 3") != std::string::npos);
    // Level of detail off: level 0 by default.
    CHECK(same(render({zarr, "--size", "32x32"}, "off.exr"),
               render({zarr, "--size", "32x32", "--zarr-level", "0"}, "off0.exr")));
}

TEST_CASE("zarr: a bad dtype, chunk size or level is one error line, status 1",
          "[zarr][errors][cli]") {
    SPARSE_DATA_OR_SKIP(data);
    const fs::path tmp = testTmpDir("zarr_bad_cli");
    const fs::path ramp = data / "dtypes" / "u2_le_zlib.zarr";
    const std::string meta = readTextFile(ramp / ".zarray");
    std::vector<std::pair<fs::path, std::string>> bad;
    for (const auto& [name, dtype] :
         {std::pair<std::string, std::string>{"complex", "\"<c8\""}, {"unknown", "\"<q3\""}}) {
        const fs::path d = copyFolder(ramp, tmp / (name + ".zarr"));
        writeText(d / ".zarray", replaced(meta, "\"<u2\"", dtype));
        bad.emplace_back(d, name == "complex" ? "complex samples" : "'<q3' is not supported");
    }
    {
        const fs::path d = copyFolder(ramp, tmp / "size.zarr");
        std::vector<unsigned char> raw(100, 7), packed(256);
        uLongf size = packed.size();
        REQUIRE(compress(packed.data(), &size, raw.data(), raw.size()) == Z_OK);
        std::ofstream(d / "1.1.1", std::ios::binary)
            .write(reinterpret_cast<const char*>(packed.data()), std::streamsize(size));
        bad.emplace_back(d, "decompresses to 100 bytes, expected 120");
    }
    {
        const fs::path d = copyFolder(data / "pyramid.zarr", tmp / "levels.zarr");
        const std::string attrs = readTextFile(d / ".zattrs");
        writeText(d / ".zattrs", replaced(attrs, "\"scale\": [\n" + std::string(32, ' ') + "1.0,",
                                          "\"scale\": [\n" + std::string(32, ' ') + "3.0,"));
        bad.emplace_back(d, "(the levels disagree)");
    }
    for (const auto& [folder, expect] : bad)
        for (const std::string command : {"render", "info"}) {
            INFO(folder.filename().string() << " " << command);
            std::vector<std::string> args = {command, folder.string()};
            if (command == "render")
                for (const std::string& a :
                     std::vector<std::string>{"--lod", "2", "-o", (tmp / "x.png").string()})
                    args.push_back(a);
            const RunResult r = runProgram(SPLAT_EXE, args);
            CHECK(r.status == 1);
            REQUIRE(r.errLines().size() == 1);
            CHECK(r.errLines()[0].rfind("splat: error: ", 0) == 0);
            CHECK(r.errLines()[0].find(expect) != std::string::npos);
            CHECK_FALSE(fs::exists(tmp / "x.png"));
        }
}
