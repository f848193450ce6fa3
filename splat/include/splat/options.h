#pragma once
// The option table: every knob a run of splat takes, once, with its long name, type, default,
// help text, --help group, what it sets (how to read the volume, the scene, one frame, the
// written image or a popping sweep) and when a run ignores it. The command line registers its
// flags from it (`--pixel-size`), the Python module reads its keyword arguments from it
// (`pixel_size=`) and scene files hold it by the long name ("pixel-size"): each reads a value
// as text and checks it here, so the three accept and refuse the same values with the same
// one-line message.
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "splat/error.h"
#include "splat/popping.h"
#include "splat/settings.h"
#include "splat/volume_io.h"

namespace splat {

enum class OptionType { Flag, Integer, Unsigned, Real, Text, TextList };
/// Paths are resolved against a scene file's folder and written absolute.
enum class OptionPath { None, Input, Output };
/// What an option sets. A Scene is built from the per-scene options; a frame of it may change
/// only the per-frame ones (Scene::frameSettings).
enum class OptionScope { Volume, Scene, Frame, Output, Sweep };
/// The option groups commands take (bits): how to read VOLUME; the rendering options (render,
/// rotate, bench, popping, study); the written image's (render, rotate); popping's sweep; the
/// Quality knobs only a study sweeps (no flag: the kernel tables' resolutions); rotate's own
/// (the sequence and where its frames go); the view commands' shared options (slices, mpr,
/// cpr: reconstruction and display window) and each view command's own; render's, popping's,
/// study's and bench's own (output, bricks, reports). Two entries may share a name only when their sets
/// are disjoint (popping's --frames and rotate's mean different things).
enum OptionSet : unsigned {
    kVolumeOptions = 1,
    kRenderOptions = 2,
    kImageOptions = 4,
    kSweepOptions = 8,
    kStudyOnlyOptions = 16,
    kRotateOptions = 32,
    kViewOptions = 64,
    kSlicesOptions = 128,
    kMprOptions = 256,
    kCprOptions = 512,
    kIsoOptions = 1024,
    kRenderCommandOptions = 2048,
    kPoppingOptions = 4096,
    kStudyOptions = 8192,
    kBenchOptions = 16384,
};
/// The sets of the options shared by several commands (what findOption(name) searches).
constexpr unsigned kSharedOptions =
    kVolumeOptions | kRenderOptions | kImageOptions | kSweepOptions | kStudyOnlyOptions;

/// What a command does with its frames, for the options only some runs use.
struct RenderUse {
    /// False when the command chooses its renderers itself (popping, study).
    bool oneRenderer = true;
    /// Extension of the images written (".png", ".exr", ...); "" when none are.
    std::string imageExt;
};

class OptionValues;

/// Why a run with `settings` ignores an option, one reason per line ("" when it applies).
using IgnoredRule = std::string (*)(const RenderSettings& settings, const RenderUse& use,
                                    const OptionValues& values);

struct OptionSpec {
    std::string_view name;  ///< long name: flag --NAME, keyword NAME ('-' -> '_'), key
    OptionType type;
    std::string_view defaultText;  ///< as --help shows it ("" for none)
    std::string_view help;
    std::string_view group;  ///< --help group
    OptionScope scope;
    OptionSet set;
    OptionPath path = OptionPath::None;
    IgnoredRule ignored = nullptr;  ///< null: every run that takes the option uses it
    std::string_view shortName = {};  ///< one letter: flag -L beside --NAME ("" for none)
};

/// Every option, in the order --help lists them and scene files hold them.
const std::vector<OptionSpec>& optionTable();
/// The options of `sets` (OptionSet bits), in table order.
std::vector<const OptionSpec*> optionsOf(unsigned sets);
/// The option named `name` among the shared options (kSharedOptions), or null.
const OptionSpec* findOption(std::string_view name);
/// The option named `name` among the options of `sets` (OptionSet bits), or null.
const OptionSpec* findOption(std::string_view name, unsigned sets);
/// The knobs `study --sweep NAME=V1,V2,...` sweeps, options of the table (their scope says
/// whether a value needs a new Scene).
const std::vector<std::string_view>& studyKnobs();
/// The type name --help shows: FLOAT, INT, UINT, TEXT.
const char* typeName(OptionType);

/// Why `text` is not a value of the option's type ("" when it is; a number for Real, an
/// integer for Integer and Unsigned, true or false for Flag). The command line prints
/// "--NAME: " before it.
std::string checkOptionText(const OptionSpec& spec, const std::string& text);

/// The values of one run's options, each at its default until set. A value's slot stays at
/// one address for the object's life (the command line binds its flags to them).
class OptionValues {
  public:
    /// Every option of `sets` (OptionSet bits) at its default.
    explicit OptionValues(unsigned sets);

    /// Sets a given value from text (a TextList appends; a Flag takes true or false). Throws
    /// OptionError "--NAME: why" for an unknown option or a malformed value.
    void set(std::string_view name, const std::string& text, bool fromScene = false);
    /// Records that the value in the slot was given (command line), or read from a scene.
    void markGiven(std::string_view name, bool fromScene);
    /// Back to the default (a run that ignores the option).
    void reset(std::string_view name);

    bool has(std::string_view name) const;
    bool given(std::string_view name) const;
    bool fromScene(std::string_view name) const;
    /// The value differs from the default (numerically for numbers).
    bool differsFromDefault(std::string_view name) const;

    const std::string& text(std::string_view name) const;
    const std::vector<std::string>& list(std::string_view name) const;
    bool flag(std::string_view name) const;
    double real(std::string_view name) const;
    long long integer(std::string_view name) const;

    /// Slots the command line binds its flags to.
    std::string& textSlot(std::string_view name);
    std::vector<std::string>& listSlot(std::string_view name);
    bool& flagSlot(std::string_view name);

    /// The options held, in table order.
    const std::vector<const OptionSpec*>& specs() const { return specs_; }

    /// A transfer function given as an object (the project's JSON text; "" none) and where it
    /// came from for messages (a scene file's name, or "").
    std::string tfInline, sceneFile;

  private:
    struct Slot {
        const OptionSpec* spec = nullptr;
        std::string text;
        std::vector<std::string> list;
        bool flag = false;
        bool given = false, fromScene = false;
    };
    Slot& slot(std::string_view name);
    const Slot& slot(std::string_view name) const;
    std::vector<const OptionSpec*> specs_;
    std::map<std::string, Slot, std::less<>> slots_;
};

/// One line of a warning (the command line prints "splat: warning: LINE").
using WarnFn = std::function<void(const std::string&)>;

// ---- rendering options ---------------------------------------------------------------

/// Settings from the values; reads no file (the transfer function stays the default).
/// Throws OptionError with the option's one-line message.
RenderSettings parseRenderOptions(const OptionValues& values);
/// Sets one rendering option (or study-only knob) of `s` from text, with the checks and
/// messages of parseRenderOptions; throws OptionError.
void applyOption(RenderSettings& s, std::string_view name, const std::string& text);
/// Every option the run ignores: one warning line each ("...; ignored"), and reset to its
/// default so that the result cannot depend on it. A value read from a scene file is reported
/// only when it differs from the default (written scenes hold every option).
void dropIgnoredOptions(OptionValues& values, const RenderSettings& settings, const RenderUse& use,
                        const WarnFn& warn);
/// Settings from the values: malformed values throw OptionError; ignored options are dropped
/// with a warning; then the transfer function (preset, file, or inline) and the label files
/// are read.
RenderSettings renderSettingsFrom(OptionValues& values, const RenderUse& use, const WarnFn& warn);
/// Defaults that depend on the data: with no tf chosen, dvr of a volume that
/// looksLikeHounsfield renders with the preset ct-hu (said through `warn` as a note); a free
/// camera's look-at point left unset becomes the volume's centre.
RenderSettings withDataDefaults(const OptionValues& values, RenderSettings s, const Volume& volume,
                                const std::function<void(const std::string&)>& note);
/// A free camera's look-at point left unset (NaN) becomes the volume's centre.
RenderSettings withFreeCameraTarget(RenderSettings s, const Volume& volume);

/// "512x512" -> (512, 512); throws OptionError naming `what`.
glm::ivec2 parseSize(const std::string& text, const std::string& what);
/// "0.4n" -> (0.4, true); "120" -> (120, false); throws OptionError otherwise.
std::pair<double, bool> parseIsoLevel(const std::string& text);
/// "1,2,3" -> {1, 2, 3}; throws OptionError naming `what` (also for NaN and infinities).
std::vector<double> parseNumbers(const std::string& text, const std::string& what);

// ---- the quality preset ---------------------------------------------------------------

/// `--quality`: one knob that sets the others (docs/speed-vs-accuracy.md "Quality presets").
/// Fast: the speed a user who accepts VTK's accuracy gets; Default: the option table's
/// defaults (today's images, bit for bit); Exact: the converged end of every knob.
enum class QualityPreset { Fast, Default, Exact };
const char* toString(QualityPreset);
/// "fast" | "default" | "exact"; throws OptionError listing them otherwise.
QualityPreset parseQualityPreset(std::string_view name);
/// The options a preset sets, by long name (the knobs of applyQualityPreset that have one).
const std::vector<std::string_view>& qualityPresetOptions();
/// Sets every knob the preset decides, except the options named in `keep` (those given
/// beside `--quality`: on the command line, as Python keywords, or in a scene file with a
/// value other than the default), which stay as they are in `s`. The one place that says
/// what each preset is.
void applyQualityPreset(RenderSettings& s, QualityPreset preset,
                        const std::vector<std::string_view>& keep = {});

// ---- volume options ------------------------------------------------------------------

/// "3" -> 3: a time step, an integer from 0; throws OptionError naming `what` otherwise.
int parseTimeStep(const std::string& text, const std::string& what);
/// How to read the volume (--dims, --type, ...); throws OptionError on a malformed value.
LoadOptions loadOptionsFrom(const OptionValues& values);
/// Loads `spec` with the options and the background value (--background-value); throws
/// splat::Error on bad input. Prints nothing.
Volume loadVolumeFrom(const std::string& spec, const OptionValues& values);

// ---- popping's sweep -----------------------------------------------------------------

/// The sweep (base camera from `settings`) and options; refuses a bad sweep or value with an
/// OptionError before anything is loaded. Leaves progress and the frame journal unset; with
/// --path the caller analyses the path instead.
void poppingFrom(const OptionValues& values, const RenderSettings& settings, Sweep& sweep,
                 PoppingOptions& options);
/// The sweep's (or --path's) views, for poppingSettings.
std::vector<CameraParams> poppingViews(const OptionValues& values, const Sweep& sweep);
/// "axis,sheet" -> {Axis, Sheet}; throws splat::Error on an unknown or empty list.
std::vector<RendererKind> parseRenderers(const std::string& text);

}  // namespace splat
