// `splat rotate VOLUME [options] --frames N [--from DEG --to DEG] [--sweep azimuth|elevation |
// --path FILE.json] [--time-steps A:B] -o DIR [--name PATTERN] [--resume | --overwrite]
// [--gif FILE] [--contact-sheet FILE] [--mp4 FILE]`: a rotation sequence through the sequence
// engine (splat/sequence.h), or one frame per time step of a time series (--time-steps: the
// camera fixed, or turning over the sequence as --from/--to or --path say). Frames are written
// atomically as they are finished, so an interrupted run leaves only complete frames, and --resume
// renders only the missing ones. The folder keeps a manifest (.splat-rotate.json) of what its
// frames show: resuming with other settings, or writing into a folder with other frames, is refused
// unless --overwrite.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>

#include "bricked_render.h"
#include "commands.h"
#include "diagnostics.h"
#include "parallel.h"
#include "progress.h"
#include "render_options.h"
#include "scene_file.h"
#include "splat/atomic_file.h"
#include "splat/error.h"
#include "splat/image_io.h"
#include "splat/sequence.h"
#include "volume_options.h"

extern char** environ;

namespace splat::cli {

namespace fs = std::filesystem;

namespace {
constexpr const char* kManifest = ".splat-rotate.json";

struct RotateCommand {
    VolumeArgs volume;
    RenderArgs render;
    std::string outDir, gif, contact, mp4, format = "png", name = "frame_%04d", sweep = "azimuth",
                                           path;
    std::string timeSteps;  // "A:B": one frame per time step A..B (inclusive)
    int firstStep = 0;      // A of --time-steps
    int frames = 36, fps = 12, parallelFrames = 0;
    double from = 0, to = 360;
    SequenceBrickArgs brick;
    bool resume = false, overwrite = false, quiet = false;
};

/// Checks a frame name pattern: exactly one integer conversion (%d, %4d, %04d), no folder.
void checkPattern(const std::string& p) {
    static const std::regex ok(R"(^[^%/]*%0?[0-9]?d[^%/]*$)");
    if (!std::regex_match(p, ok))
        throw Error("--name '" + p + "' must hold exactly one %d (e.g. frame_%04d) and no '/'");
}

std::string frameFile(const RotateCommand& a, std::size_t f) {
    char name[512];
    std::snprintf(name, sizeof name, a.name.c_str(), int(f));
    return (fs::path(a.outDir) / (std::string(name) + "." + a.format)).string();
}

/// Files in the folder that look like frames of this pattern, with their index.
std::vector<std::pair<std::size_t, fs::path>> existingFrames(const RotateCommand& a) {
    const std::string p = a.name;
    const std::size_t pc = p.find('%'), d = p.find('d', pc);
    const auto esc = [](const std::string& s) {
        return std::regex_replace(s, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)");
    };
    const std::regex re("^" + esc(p.substr(0, pc)) + "([0-9]+)" + esc(p.substr(d + 1)) + "\\." +
                        esc(a.format) + "$");
    std::vector<std::pair<std::size_t, fs::path>> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(a.outDir, ec)) {
        std::smatch m;
        const std::string file = e.path().filename().string();
        if (std::regex_match(file, m, re)) out.emplace_back(std::stoul(m[1].str()), e.path());
    }
    return out;
}

/// What the frames show: settings that must match for --resume.
nlohmann::json manifestOf(const RotateCommand& a, const RenderSettings& s) {
    return {{"volume", a.volume.spec},
            {"frames", a.frames},
            {"from", a.from},
            {"to", a.to},
            {"sweep", a.sweep},
            {"path", a.path},
            {"name", a.name},
            {"format", a.format},
            {"renderer", toString(s.renderer)},
            {"mode", toString(s.mode)},
            {"classify", toString(s.classification)},
            {"tf", a.render.values.tfInline.empty() ? nlohmann::json(a.render.values.text("tf")) : nlohmann::json::parse(a.render.values.tfInline)},
            {"size", a.render.size()},
            {"azimuth", s.camera.azimuthDeg},
            {"elevation", s.camera.elevationDeg},
            {"slab", s.quality.slab},
            {"projection", toString(s.camera.projection)},
            {"shade", s.shading.enabled},
            {"time_steps", a.timeSteps}};
}

/// "A:B" of --time-steps: the first and last time step, 0 <= A <= B.
std::pair<int, int> parseTimeSteps(const std::string& text) {
    const std::size_t colon = text.find(':');
    if (colon == std::string::npos)
        throw Error("--time-steps '" + text + "': expected A:B, the first and last time step");
    const int first = parseTimeStep(text.substr(0, colon), "--time-steps");
    const int last = parseTimeStep(text.substr(colon + 1), "--time-steps");
    if (last < first) throw Error("--time-steps '" + text + "': the last step is before the first");
    return {first, last};
}

/// The frames of a time series (--time-steps), in this process: frame f shows time step
/// a.firstStep + f from path.views[f], its volume loaded and classified with `settings` (the
/// first step's data defaults, so every frame has the same transfer function and window).
void renderTimeSteps(const RotateCommand& a, const std::shared_ptr<const Volume>& first,
                     const RenderSettings& settings, const CameraPath& path,
                     const std::vector<bool>& keep, ProgressReporter& progress,
                     const std::function<void(std::size_t, const Image&, double)>& emit) {
    std::size_t pending = 0, done = 0;
    for (bool k : keep) pending += k ? 0 : 1;
    for (std::size_t f = 0; f < path.views.size(); ++f) {
        if (keep[f]) continue;
        const auto t = std::chrono::steady_clock::now();
        std::shared_ptr<const Volume> volume = first;
        if (f > 0) {
            VolumeArgs step = a.volume;
            step.values.set("time", std::to_string(a.firstStep + int(f)));
            volume = std::make_shared<const Volume>(loadVolumeFrom(step.spec, step.values));
        }
        const Scene scene(volume, settings);
        const Image image = scene.render(settings.renderer, path.views[f]);
        emit(f, image,
             std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t)
                 .count());
        if (!progress(++done, pending, "time step " + std::to_string(a.firstStep + int(f))))
            throw Cancelled();
    }
}

/// True when `file` decodes as a complete image of width x height pixels.
bool frameIsComplete(const fs::path& file, int width, int height) {
    try {
        const Image im = readImage(file.string());
        return im.width == width && im.height == height;
    } catch (const std::exception&) {
        return false;
    }
}

/// Refuses folders whose frames would be mixed with this run's; returns the frames to keep
/// (those that decode completely, `width` x `height`).
std::vector<bool> prepareFolder(const RotateCommand& a, const nlohmann::json& manifest, int width,
                                int height) {
    std::error_code ec;
    if (fs::exists(a.outDir, ec) && !fs::is_directory(a.outDir, ec))
        throw Error(a.outDir + ": exists and is not a folder");
    std::vector<bool> keep(std::size_t(a.frames), false);
    if (!fs::is_directory(a.outDir, ec)) return keep;
    removeStaleTemporaries(a.outDir);  // left by a killed run
    const auto frames = existingFrames(a);
    if (frames.empty()) return keep;
    const fs::path mpath = fs::path(a.outDir) / kManifest;
    bool same = false;
    if (std::ifstream in(mpath); in) {
        try {
            nlohmann::json old = nlohmann::json::parse(in);
            old.erase("window");
            same = old == manifest;
        } catch (const std::exception&) {
        }
    }
    if (a.overwrite) {
        for (const auto& [i, p] : frames) fs::remove(p, ec);
        return keep;
    }
    if (!a.resume)
        throw Error(a.outDir + " already holds " + std::to_string(frames.size()) +
                    " frames; use --resume to finish them or --overwrite to replace them");
    if (!same)
        throw Error(a.outDir + ": its frames were rendered with other settings (" + kManifest +
                    "); use --overwrite to replace them");
    for (const auto& [i, p] : frames) {
        if (i >= keep.size())
            throw Error(a.outDir + ": holds frame " + std::to_string(i) + " beyond --frames " +
                        std::to_string(a.frames) + "; use --overwrite");
        // Only a frame that decodes to the right size is kept; any other is rendered again
        // (a file damaged or truncated after it was written, or by another program).
        keep[i] = frameIsComplete(p, width, height);
        if (!keep[i]) warn(p.string() + ": incomplete or unreadable frame; rendering it again");
    }
    return keep;
}

std::string findProgram(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::string dirs = path ? path : "/usr/bin:/bin";
    std::size_t start = 0;
    while (start <= dirs.size()) {
        const std::size_t end = std::min(dirs.find(':', start), dirs.size());
        const fs::path p = fs::path(dirs.substr(start, end - start)) / name;
        if (::access(p.c_str(), X_OK) == 0) return p.string();
        start = end + 1;
    }
    return {};
}

/// Encodes the PNG frames into an MP4 with the ffmpeg program, atomically.
void writeMp4(const RotateCommand& a, const std::string& ffmpeg) {
    AtomicFile out(a.mp4);
    const std::string input = (fs::path(a.outDir) / (a.name + ".png")).string();
    const std::string fps = std::to_string(a.fps), tmp = out.temporary().string();
    std::vector<std::string> args = {"ffmpeg",
                                     "-loglevel",
                                     "error",
                                     "-nostdin",
                                     "-y",
                                     "-framerate",
                                     fps,
                                     "-start_number",
                                     "0",
                                     "-i",
                                     input,
                                     "-vf",
                                     "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                     "-c:v",
                                     "libx264",
                                     "-pix_fmt",
                                     "yuv420p",
                                     tmp};
    std::vector<char*> argv;
    for (auto& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    // ffmpeg's messages are collected, and its last line becomes our one-line error.
    int pipeFd[2];
    if (::pipe(pipeFd) != 0) throw Error(a.mp4 + ": cannot run " + ffmpeg);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipeFd[1], 2);
    posix_spawn_file_actions_addclose(&actions, pipeFd[0]);
    pid_t pid;
    const int spawned = posix_spawn(&pid, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(pipeFd[1]);
    std::string messages;
    char buf[4096];
    for (ssize_t n; spawned == 0 && (n = ::read(pipeFd[0], buf, sizeof buf)) != 0;)
        if (n > 0)
            messages.append(buf, std::size_t(n));
        else if (errno != EINTR)
            break;
    ::close(pipeFd[0]);
    if (spawned != 0) throw Error(a.mp4 + ": cannot run " + ffmpeg);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        while (!messages.empty() && std::isspace((unsigned char)messages.back()))
            messages.pop_back();
        const std::size_t nl = messages.rfind('\n');
        const std::string last = nl == std::string::npos ? messages : messages.substr(nl + 1);
        throw Error(a.mp4 + ": ffmpeg failed (" +
                    (last.empty() ? "exit status " + std::to_string(WEXITSTATUS(status)) : last) +
                    ")");
    }
    out.commit();
}

/// Refuses an extra output (GIF, contact sheet, MP4) that could not be written, before any
/// frame is rendered: its folder is created, and must be writable.
void checkExtraOutput(const std::string& path, const char* flag) {
    if (path.empty()) return;
    std::error_code ec;
    if (fs::is_directory(path, ec))
        throw Error(path + ": " + flag + " needs a file name, not a folder");
    fs::path parent = fs::path(path).parent_path();
    if (parent.empty()) parent = ".";
    fs::create_directories(parent, ec);
    if (!fs::is_directory(parent, ec))
        throw Error(path + ": cannot create the folder '" + parent.string() + "'");
    if (::access(parent.c_str(), W_OK) != 0)
        throw Error(path + ": the folder '" + parent.string() + "' is not writable");
}
/// The frames of a bricked sequence (docs/parallel.md), on every rank of
/// `group`: each loads its bricks and builds their Scenes once, then every view not kept is
/// rendered by them and composited; rank 0 hands it to `emit` (view, image, milliseconds).
/// A failure on rank 0 (writing a frame) or on any rank ends every rank at the next frame.
void renderBrickedFrames(const RotateCommand& a, const Volume& geometry,
                         const RenderSettings& settings, int bricks, BrickGroup& group,
                         const CameraPath& path, const std::vector<bool>& keep,
                         ProgressReporter& progress,
                         const std::function<void(std::size_t, const Image&, double)>& emit) {
    const bool leader = group.rank() == 0;
    if (leader && settings.renderer == RendererKind::Sheet && a.brick.composite == "fast")
        warn(
            "--renderer sheet with --brick-composite fast is approximate where its slabs cross a "
            "brick face (docs/parallel.md); --brick-composite exact is not");
    BrickedFrames frames(
        geometry, brickLoader(a.volume), settings, bricks, group,
        a.brick.composite == "exact" ? BrickComposite::Exact : BrickComposite::Fast, true,
        brickEmptiness(a.volume));
    std::size_t pending = 0, done = 0;
    for (bool k : keep) pending += k ? 0 : 1;
    std::string failure;
    for (std::size_t v = 0; v < path.views.size(); ++v) {
        group.agree(failure);
        if (keep[v]) continue;
        const auto t = std::chrono::steady_clock::now();
        const Image image = frames.render(path.views[v]);
        if (!leader) continue;
        try {
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t)
                    .count();
            emit(v, image, ms);
            if (!progress(++done, pending, "view " + std::to_string(v)))
                throw Error("interrupted after " + std::to_string(done) +
                            " new frames; the frames written are complete (--resume finishes "
                            "them)");
        } catch (const std::exception& e) {
            failure = e.what();
        }
    }
    group.agree(failure);
    const std::vector<BrickStats> all = group.gather(frames.stats());
    if (!leader || a.quiet) return;
    progress.finish();
    printRankStats(all, pending, " once");
}
}  // namespace

namespace {

/// The options of `splat rotate` besides the volume and rendering options.
void addRotateOptions(CLI::App& cmd, RotateCommand& a) {
    constexpr unsigned R = kRotateOptions;
    addTableOption(cmd, "frames", a.frames, R);
    addTableOption(cmd, "from", a.from, R);
    addTableOption(cmd, "to", a.to, R);
    addTableOption(cmd, "sweep", a.sweep, R);
    addTableOption(cmd, "path", a.path, R);
    addTableOption(cmd, "time-steps", a.timeSteps, R);
    addTableOption(cmd, "parallel-frames", a.parallelFrames, R);
    addSequenceBrickOptions(cmd, a.brick, R);
    addTableOption(cmd, "output", a.outDir, R);
    addTableOption(cmd, "name", a.name, R);
    addTableOption(cmd, "format", a.format, R);
    addTableOption(cmd, "resume", a.resume, R);
    addTableOption(cmd, "overwrite", a.overwrite, R);
    addTableOption(cmd, "gif", a.gif, R);
    addTableOption(cmd, "contact-sheet", a.contact, R);
    addTableOption(cmd, "mp4", a.mp4, R);
    addTableOption(cmd, "fps", a.fps, R);
    addTableOption(cmd, "quiet", a.quiet, R);
}

/// --time-steps A:B: sets --frames and the first frame's --time; refuses --time, a --frames
/// that disagrees and mpirun.
void checkTimeSteps(const CLI::App& cmd, RotateCommand& a) {
    if (!a.volume.values.text("time").empty())
        throw Error("--time-steps and --time exclude each other");
    const auto [first, last] = parseTimeSteps(a.timeSteps);
    const long long n = (long long)last - first + 1;
    if (n > 100000) throw Error("--time-steps: at most 100000 frames");
    if (given(cmd, "frames") && a.frames != n)
        throw Error("--frames " + std::to_string(a.frames) + " and --time-steps " + a.timeSteps +
                    " (" + std::to_string(n) + " frames) disagree; give one of them");
    a.frames = int(n);
    a.firstStep = first;
    a.volume.values.set("time", std::to_string(first));  // the first frame's volume
    if (processCount() > 1) throw Error("--time-steps renders in one process (without mpirun)");
}

/// Refuses what cannot run before anything is rendered or created, and warns about the
/// options the run ignores.
void checkRotateArgs(const CLI::App& cmd, RotateCommand& a) {
    asUsage([&] {
        if (a.frames < 1 || a.frames > 100000)
            throw Error("--frames must be between 1 and 100000");
        if (a.fps < 1 || a.fps > 100) throw Error("--fps must be between 1 and 100");
        if (a.parallelFrames < 0 || a.parallelFrames > 1024)
            throw Error("--parallel-frames must be between 0 and 1024");
        if (!std::isfinite(a.from) || !std::isfinite(a.to) || std::abs(a.from) > 1e6 ||
            std::abs(a.to) > 1e6)
            throw Error("--from and --to must be finite angles (degrees)");
        if (a.format != "png" && a.format != "exr" && a.format != "tif")
            throw Error("--format must be png, exr or tif");
        if (a.sweep != "azimuth" && a.sweep != "elevation")
            throw Error("--sweep must be azimuth or elevation");
        if (a.resume && a.overwrite)
            throw Error("--resume and --overwrite exclude each other");
        checkPattern(a.name);
        if (!a.gif.empty() && lowerExtension(a.gif) != ".gif")
            throw Error(a.gif + ": --gif needs a .gif file name");
        if (!a.contact.empty()) checkImageExtension(a.contact);
        if (!a.mp4.empty() && lowerExtension(a.mp4) != ".mp4")
            throw Error(a.mp4 + ": --mp4 needs a .mp4 file name");
        if (!a.mp4.empty() && a.format != "png")
            throw Error("--mp4 is made from png frames (--format png)");
        if (!a.timeSteps.empty()) checkTimeSteps(cmd, a);
    });
    if (!a.path.empty())
        for (const char* k : {"from", "to", "sweep"})
            if (given(cmd, k) && !fromScene(cmd, k))
                warn(std::string("--") + k + " does not apply with --path (the path's keys " +
                     "set the views); ignored");
    if (a.gif.empty() && a.mp4.empty() && given(cmd, "fps") && !fromScene(cmd, "fps"))
        warn("--fps applies to --gif and --mp4 only; ignored");
}

/// The views: a turn of the swept angle, or the camera path of --path.
CameraPath rotatePath(const CLI::App& cmd, const RotateCommand& a, const RenderSettings& settings) {
    if (!a.path.empty()) return CameraPath::fromJson(a.path, settings.camera, a.frames);
    const double to = given(cmd, "to") ? a.to : a.from + 360.0 * (a.frames - 1) / a.frames;
    return CameraPath::turn(settings.camera,
                            a.sweep == "azimuth" ? CameraPath::Angle::Azimuth
                                                 : CameraPath::Angle::Elevation,
                            a.from, to, a.frames);
}

/// The display window (mip, xray) is fixed by the first frame a folder gets, and kept in the
/// manifest so that resumed frames match: the window of a resumed folder, if it has one.
std::optional<WriteOptions> resumedWindow(const RotateCommand& a) {
    if (!a.resume) return std::nullopt;
    std::ifstream in(fs::path(a.outDir) / kManifest);
    if (!in) return std::nullopt;
    try {
        const nlohmann::json old = nlohmann::json::parse(in);
        if (!old.contains("window")) return std::nullopt;
        WriteOptions w;
        w.mapping = DisplayMapping::Window;
        w.windowLow = old["window"][0].get<float>();
        w.windowHigh = old["window"][1].get<float>();
        return withMetadata(w);
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

/// The GIF and contact sheet of the frames (those kept from an earlier run read back).
void writeGifAndContactSheet(const RotateCommand& a, std::vector<Image>& shown,
                             const std::vector<bool>& keep,
                             const std::optional<WriteOptions>& display) {
    for (std::size_t f = 0; f < shown.size(); ++f)
        if (keep[f]) {
            const Image im = readImage(frameFile(a, f));
            shown[f] = a.format == "png" || !display ? im : toDisplay(im, *display);
        }
    WriteOptions asIs;
    asIs.mapping = DisplayMapping::Display;
    if (!a.gif.empty()) writeAnimatedGif(a.gif, shown, asIs, a.fps);
    if (!a.contact.empty()) {
        std::vector<Image> small;
        for (const Image& im : shown) small.push_back(downscale(im, 160));
        writeImage(a.contact, contactSheet(small), withMetadata(asIs));
    }
}

/// What the steps of one rotate run share.
struct RotateRun {
    RenderSettings settings;
    SequenceBricks bricks;  ///< bricks > 0: a bricked sequence
    std::unique_ptr<BrickGroup> group;
    bool leader = true;       ///< rank 0 (or the only process): prepares and writes the outputs
    bool keepImages = false;  ///< frames kept in memory for the GIF and contact sheet
    std::string ffmpeg;
    CameraPath path;
    nlohmann::json manifest;
    std::vector<bool> keep;  ///< frames already in the folder (--resume)
    std::shared_ptr<const Volume> volume;
    std::optional<Scene> scene;
    std::optional<WriteOptions> display;
    std::vector<Image> shown;
    double totalMs = 0;
    std::size_t rendered = 0;

    bool bricked() const { return bricks.bricks > 0; }
};

/// The settings, once everything that can be refused without reading the volume is refused.
RenderSettings checkedSettings(CLI::App& cmd, RotateCommand& a) {
    prepareCommand(cmd, {"volume", "output"});
    checkRotateArgs(cmd, a);
    checkSequenceBrickOptions(cmd, a.brick);
    RenderUse use;
    use.imageExt = "." + a.format;
    RenderSettings settings = settingsFromArgs(a.render, use);
    loadOptionsFromArgs(a.volume);
    chooseZarrLevel(a.volume, settings);
    return settings;
}

/// Bricks, or frames in parallel (docs/parallel.md, chooseSequenceBricks), with the warnings
/// and refusals of that choice.
void chooseBricks(const CLI::App& cmd, RotateCommand& a, RotateRun& run) {
    run.bricks = chooseSequenceBricks(a.volume, run.settings, a.brick.bricks, a.brick.rankMemory);
    if (run.bricked() && !a.timeSteps.empty())
        throw UsageError("--time-steps renders without bricks (no --bricks or --rank-memory)");
    if (run.bricked() && !run.bricks.alone && !workerProcess())
        warn(a.volume.spec +
             ": its samples are not read by brick (DICOM, a slice folder, NRRD text or hex, "
             "an ANALYZE pair): every rank loads the whole volume once and keeps its brick");
    if (given(cmd, "brick-composite") && !fromScene(cmd, "brick-composite") &&
        (!run.bricked() || run.settings.renderer != RendererKind::Sheet) && !workerProcess())
        warn(
            "--brick-composite applies to bricked sequences (--bricks, or mpirun when the "
            "volume does not fit one process) of --renderer sheet: ignored");
}

/// The views: a time series' camera turns only when --from/--to (or --path) say so.
CameraPath cameraPath(const CLI::App& cmd, const RotateCommand& a, const RenderSettings& settings) {
    const bool fixedCamera =
        !a.timeSteps.empty() && a.path.empty() && !given(cmd, "from") && !given(cmd, "to");
    return fixedCamera
               ? CameraPath{std::vector<CameraParams>(std::size_t(a.frames), settings.camera)}
               : rotatePath(cmd, a, settings);
}

/// The extra outputs' programs, folders and memory, refused before anything is rendered.
void checkExtraOutputs(const RotateCommand& a, RotateRun& run) {
    if (!a.mp4.empty()) {
        run.ffmpeg = findProgram("ffmpeg");
        if (run.ffmpeg.empty())
            throw Error(
                "--mp4 needs the ffmpeg program, which is not installed "
                "(Debian: apt-get install ffmpeg)");
    }
    checkExtraOutput(a.gif, "--gif");
    checkExtraOutput(a.contact, "--contact-sheet");
    checkExtraOutput(a.mp4, "--mp4");
    const CameraParams& c = run.settings.camera;
    if (run.keepImages && double(a.frames) * c.width * c.height > double(1 << 28))
        throw Error("--gif/--contact-sheet with " + std::to_string(a.frames) + " frames of " +
                    a.render.size() +
                    " would not fit in memory; use fewer frames or a smaller --size");
}

/// Rank 0's preparation: outputs checked, the folder's kept frames, the run fixed, the scene
/// loaded (without bricks), the output folder created.
void prepareOutputs(const CLI::App& cmd, RotateCommand& a, RotateRun& run) {
    checkExtraOutputs(a, run);
    run.keep =
        prepareFolder(a, run.manifest, run.settings.camera.width, run.settings.camera.height);
    beginRun(cmd);
    if (!run.bricked()) {
        run.volume = std::make_shared<const Volume>(loadVolumeFromArgs(a.volume));
        run.settings = withDataDefaults(a.render, run.settings, *run.volume);
        run.scene.emplace(run.volume, run.settings);
    }
    if (!a.timeSteps.empty() && a.frames > 1) {
        // The last step is loaded once up front: a step past the file's last is a usage
        // error before any frame is rendered.
        VolumeArgs last = a.volume;
        last.values.set("time", std::to_string(a.firstStep + a.frames - 1));
        (void)loadVolumeFrom(last.spec, last.values);
    }
    std::error_code ec;
    fs::create_directories(a.outDir, ec);
    if (!fs::is_directory(a.outDir)) throw Error(a.outDir + ": cannot create output folder");
    run.display = resumedWindow(a);
}

/// Rank 0 prepares the outputs; a bricked run's other ranks learn whether it could, and which
/// frames are kept (--resume), before rendering with it.
void prepareRun(const CLI::App& cmd, RotateCommand& a, RotateRun& run) {
    std::string failure;
    try {
        if (run.leader) prepareOutputs(cmd, a, run);
    } catch (const std::exception& e) {
        if (!run.bricked()) throw;
        failure = e.what();
    }
    if (run.bricked()) {
        run.group->agree(failure);
        std::vector<unsigned char> kept(run.keep.begin(), run.keep.end());
        run.group->broadcast(kept);
        run.keep.assign(kept.begin(), kept.end());
    }
}

/// One finished frame (rank 0): written, and kept for the GIF and contact sheet.
void emitFrame(const RotateCommand& a, RotateRun& run, std::size_t view, const Image& image,
               double ms) {
    if (!run.display) {
        run.display = displayOptions(a.render, run.settings, image);
        if (run.display->mapping == DisplayMapping::Window)
            run.manifest["window"] = {run.display->windowLow, run.display->windowHigh};
        writeTextAtomic(fs::path(a.outDir) / kManifest, run.manifest.dump(2) + "\n");
    }
    writeImage(frameFile(a, view), image, *run.display);
    run.totalMs += ms;
    ++run.rendered;
    if (run.keepImages) run.shown[view] = toDisplay(image, *run.display);
}

/// The frames not kept: bricked, one per time step, or through the sequence engine.
void renderFrames(const RotateCommand& a, RotateRun& run, ProgressReporter& progress) {
    run.shown.resize(run.keepImages ? std::size_t(a.frames) : 0);
    SequenceOptions so;
    so.parallelFrames = a.parallelFrames;
    so.skip = [&](std::size_t v) { return run.keep[v]; };
    so.progress = [&](std::size_t d, std::size_t t, const std::string& w) {
        return progress(d, t, w);
    };
    const auto emit = [&](std::size_t view, const Image& image, double ms) {
        emitFrame(a, run, view, image, ms);
    };
    try {
        if (run.bricked())
            renderBrickedFrames(a, *run.bricks.geometry, run.settings, run.bricks.bricks,
                                *run.group, run.path, run.keep, progress, emit);
        else if (!a.timeSteps.empty())
            renderTimeSteps(a, run.volume, run.settings, run.path, run.keep, progress, emit);
        else
            renderSequence(
                *run.scene, {run.settings.renderer}, run.path, so,
                [&](SequenceFrame&& f) { emit(f.view, f.images[0], f.stats[0].milliseconds); });
    } catch (const Cancelled&) {
        progress.finish();
        throw Error("interrupted after " + std::to_string(run.rendered) +
                    " new frames; the frames written are complete (--resume finishes them)");
    }
}

/// Rank 0's last step: the manifest of a run that rendered nothing, the GIF, contact sheet and
/// MP4, and the summary line.
void finishOutputs(const CLI::App& cmd, const RotateCommand& a, RotateRun& run) {
    if (run.rendered == 0 && !fs::exists(fs::path(a.outDir) / kManifest))
        writeTextAtomic(fs::path(a.outDir) / kManifest, run.manifest.dump(2) + "\n");
    if (run.keepImages) writeGifAndContactSheet(a, run.shown, run.keep, run.display);
    if (!a.mp4.empty()) writeMp4(a, run.ffmpeg);
    std::printf("wrote %zu frames to %s (%zu kept)%s%s%s%s%s%s (%.1f ms per frame)\n", run.rendered,
                a.outDir.c_str(), std::size_t(a.frames) - run.rendered, a.gif.empty() ? "" : ", ",
                a.gif.c_str(), a.contact.empty() ? "" : ", ", a.contact.c_str(),
                a.mp4.empty() ? "" : ", ", a.mp4.c_str(),
                run.rendered ? run.totalMs / double(run.rendered) : 0.0);
    finishRun(cmd);
}

/// The rotate command: everything that can be refused is refused before anything is rendered
/// or created; then the outputs are prepared, the frames rendered and the extras written.
void runRotate(CLI::App& cmd, RotateCommand& a) {
    RotateRun run;
    run.settings = checkedSettings(cmd, a);
    chooseBricks(cmd, a, run);
    if (!run.bricked() && workerProcess())  // under mpirun: render the frames rank 0 asks for
        return serveFrames([&] {
            auto v = std::make_shared<const Volume>(loadVolumeFromArgs(a.volume));
            return Scene(v, withDataDefaults(a.render, run.settings, *v));
        });
    run.leader = !workerProcess();
    if (run.bricked()) run.group = brickGroup(a.brick.compositor);
    run.keepImages = !a.gif.empty() || !a.contact.empty();
    run.path = cameraPath(cmd, a, run.settings);
    run.manifest = manifestOf(a, run.settings);
    run.keep.assign(std::size_t(a.frames), false);
    prepareRun(cmd, a, run);
    installInterruptHandler();
    ProgressReporter progress("frames", a.quiet || !run.leader);
    renderFrames(a, run, progress);
    if (!run.leader) return;
    progress.finish();
    finishOutputs(cmd, a, run);
}

}  // namespace

void registerRotate(CLI::App& app) {
    auto a = std::make_shared<RotateCommand>();
    CLI::App* cmd = app.add_subcommand("rotate", "render a rotation sequence or a camera path");
    addVolumeOptions(*cmd, a->volume);
    addRenderOptions(*cmd, a->render, true);
    addRotateOptions(*cmd, *a);
    cmd->footer(
        "Examples:\n"
        "  splat rotate ch2.nii.gz --tf mri-head --frames 36 -o turn --gif turn.gif\n"
        "  splat rotate synthetic:phantom:64 --sweep elevation --from -30 --to 30 --frames 13 -o "
        "tilt\n"
        "  splat rotate ch2.nii.gz --path path.json --frames 120 -o fly --mp4 fly.mp4 --fps 30");
    cmd->callback([a, cmd] { runRotate(*cmd, *a); });
}

}  // namespace splat::cli
