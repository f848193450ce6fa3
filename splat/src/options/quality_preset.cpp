// The quality preset (`--quality fast|default|exact`, see splat/options.h): one knob that sets
// the knobs trading speed for accuracy. The figures each preset was chosen from are in
// docs/speed-vs-accuracy.md "Quality presets".
#include <algorithm>

#include "splat/options.h"

namespace splat {

namespace {

/// One preset's values of the knobs it sets.
struct PresetValues {
    double earlyTermination;  ///< early-termination
    double slab;              ///< slab (image-aligned splatter), voxels
    double referenceStep;     ///< ref-step (0: automatic)
    double referenceTolerance;
    int factorisedSheets;  ///< Quality::factorisedSheets (no option of its own)
};

PresetValues valuesOf(QualityPreset preset) {
    switch (preset) {
        case QualityPreset::Fast:
            // Axis-aligned: factorised sheets at one sample per voxel and early termination
            // at 1/32 (ch2 at 512²: RMSE 2.2e-3 to 2.4e-3, within VTK's 2.7e-3 at 1-voxel
            // steps, at 0.18x the default's CPU time); image-aligned: slabs of 2 voxels; the
            // reference: a tenfold looser step refinement.
            return {1.0 / 32.0, 2.0, 0.0, 1e-3, 1};
        case QualityPreset::Exact:
            // The converged end (docs/speed-vs-accuracy.md "Convergence orders"): no early
            // termination, quarter-voxel slabs, the reference at the study's truth settings.
            return {0.0, 0.25, 0.125, 1e-5, 0};
        case QualityPreset::Default:
            break;
    }
    // The option table's defaults.
    return {1.0 / 256.0, 1.0, 0.0, 1e-4, 0};
}

}  // namespace

const char* toString(QualityPreset preset) {
    switch (preset) {
        case QualityPreset::Fast:
            return "fast";
        case QualityPreset::Exact:
            return "exact";
        case QualityPreset::Default:
            break;
    }
    return "default";
}

QualityPreset parseQualityPreset(std::string_view name) {
    for (QualityPreset p : {QualityPreset::Fast, QualityPreset::Default, QualityPreset::Exact})
        if (name == toString(p)) return p;
    throw OptionError("--quality '" + std::string(name) + "' must be fast, default or exact");
}

const std::vector<std::string_view>& qualityPresetOptions() {
    static const std::vector<std::string_view> names = {"early-termination", "slab", "ref-step",
                                                        "ref-tolerance"};
    return names;
}

void applyQualityPreset(RenderSettings& s, QualityPreset preset,
                        const std::vector<std::string_view>& keep) {
    const PresetValues v = valuesOf(preset);
    const auto set = [&](std::string_view option, auto& knob, auto value) {
        if (std::find(keep.begin(), keep.end(), option) == keep.end()) knob = value;
    };
    Quality& q = s.quality;
    set("early-termination", q.earlyTermination, v.earlyTermination);
    set("slab", q.slab, v.slab);
    set("ref-step", q.referenceStep, v.referenceStep);
    set("ref-tolerance", q.referenceTolerance, v.referenceTolerance);
    q.factorisedSheets = v.factorisedSheets;
}

}  // namespace splat
