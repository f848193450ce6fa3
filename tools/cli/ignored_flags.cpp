// The one place that decides which options a run ignores (README "Command line",
// warnings): each gets one line `splat: warning: ...; ignored` and is reset to its default,
// so that the picture is the same with and without it. A key read from a scene file is
// reported only when its value differs from the default (written scenes hold every option).
#include "diagnostics.h"
#include "render_options.h"
#include "scene_file.h"

namespace splat::cli {

void dropIgnoredOptions(RenderArgs& a, const RenderSettings& s, const RenderUse& use) {
    const CLI::App& cmd = *a.cmd;
    const RenderArgs d;
    TechniqueArgs& t = a.technique;
    const TechniqueArgs td;
    auto drop = [&](const char* key, bool differs, const std::string& why, auto reset) {
        if (!given(cmd, key) || (fromScene(cmd, key) && !differs)) return;
        warn(why + "; ignored");
        reset();
    };
    const std::string mode = toString(s.mode), renderer = toString(s.renderer);
    const bool projective = s.mode == RenderMode::Xray || s.mode == RenderMode::Mip;
    const bool perspective = s.camera.projection == Projection::Perspective;

    if (use.oneRenderer) {
        if (s.renderer != RendererKind::Sheet)
            drop("slab", a.slab != d.slab,
                 "--slab applies to the sheet renderer (image-aligned slabs), not to " + renderer,
                 [&] { a.slab = d.slab; });
        // The splatters hand pixels to the reference ray caster only in perspective views
        // from within the volume.
        if (s.renderer != RendererKind::Reference && !perspective) {
            drop("ref-step", a.refStep != d.refStep,
                 "--ref-step applies to the reference renderer, not to " + renderer,
                 [&] { a.refStep = d.refStep; });
            drop("ref-tolerance", a.refTolerance != d.refTolerance,
                 "--ref-tolerance applies to the reference renderer, not to " + renderer,
                 [&] { a.refTolerance = d.refTolerance; });
        }
        if (s.renderer == RendererKind::Reference) {
            drop("tile-size", a.tileSize != d.tileSize,
                 "--tile-size applies to the splatters, not to the reference renderer",
                 [&] { a.tileSize = d.tileSize; });
            drop("early-termination", a.earlyTermination != d.earlyTermination,
                 "--early-termination applies to the splatters, not to the reference renderer",
                 [&] { a.earlyTermination = d.earlyTermination; });
            drop("lod", a.lod != d.lod,
                 "--lod applies to the splatters, not to the reference renderer",
                 [&] { a.lod = d.lod; });
            drop("ewa", a.ewa != d.ewa,
                 "--ewa applies to the splatters, not to the reference renderer "
                 "(use --pixel-filter)",
                 [&] { a.ewa = d.ewa; });
        } else if (s.quality.ewa == Ewa::Off) {
            drop("pixel-filter", a.pixelFilter != d.pixelFilter,
                 "--pixel-filter applies to the reference and to --ewa on|auto, not to " +
                     renderer + " with --ewa off",
                 [&] { a.pixelFilter = d.pixelFilter; });
        }
    }
    if (s.mode != RenderMode::Dvr)
        drop("order", a.order != d.order,
             "--order applies to dvr only (" + mode + " does not depend on the compositing order)",
             [&] { a.order = d.order; });
    else if (s.order == CompositeOrder::BackToFront)
        drop("early-termination", a.earlyTermination != d.earlyTermination,
             "--early-termination applies to front-to-back compositing, not to --order btf",
             [&] { a.earlyTermination = d.earlyTermination; });
    if (projective) {
        drop("classify", a.classify != d.classify,
             "--classify " + a.classify + " does not apply to " + mode + " (no transfer function)",
             [&] { a.classify = d.classify; });
        drop("shade", a.shade != d.shade,
             "--shade: shading does not apply to " + mode + " (no surfaces or emission to light)",
             [&] { a.shade = d.shade; });
    }
    const std::string noShade =
        projective ? " does not apply to " + mode : " given without --shade";
    if (!a.shade) {
        drop("ambient", t.ambient != td.ambient, "--ambient" + noShade,
             [&] { t.ambient = td.ambient; });
        drop("diffuse", t.diffuse != td.diffuse, "--diffuse" + noShade,
             [&] { t.diffuse = td.diffuse; });
        drop("specular", t.specular != td.specular, "--specular" + noShade,
             [&] { t.specular = td.specular; });
        drop("shininess", t.shininess != td.shininess, "--shininess" + noShade,
             [&] { t.shininess = td.shininess; });
        drop("light", t.light != td.light, "--light" + noShade, [&] { t.light = td.light; });
    }
    if (s.mode != RenderMode::Dvr)
        drop("edges", !t.edges.empty(),
             "--edges: edge enhancement scales dvr opacity; not used in " + mode,
             [&] { t.edges.clear(); });
    if (s.mode != RenderMode::Iso) {
        drop("iso-level", a.isoLevel != d.isoLevel,
             "--iso-level applies to iso mode only, not to " + mode,
             [&] { a.isoLevel = d.isoLevel; });
        drop("iso-normalized", t.isoNormalized,
             "--iso-normalized applies to iso mode only, not to " + mode,
             [&] { t.isoNormalized = td.isoNormalized; });
    }
    if (!perspective) {
        drop("fov", a.fov != d.fov, "--fov applies to --projection perspective only",
             [&] { a.fov = d.fov; });
        drop("distance", a.distance != d.distance,
             "--distance applies to --projection perspective only",
             [&] { a.distance = d.distance; });
    }
    const std::string& ext = use.imageExt;
    const bool eightBit = ext == ".png" || ext == ".gif" || ext == ".jpg" || ext == ".jpeg";
    if (!projective)
        drop("window", !a.window.empty(),
             "--window applies to mip and xray (" + mode + " images are written sRGB)",
             [&] { a.window.clear(); });
    else if (!eightBit)
        drop("window", !a.window.empty(),
             "--window applies to 8-bit images (.png); " + ext + " holds the values as computed",
             [&] { a.window.clear(); });
    if (ext != ".png") {
        drop("bit-depth", t.bitDepth != td.bitDepth, "--bit-depth applies to .png images only",
             [&] { t.bitDepth = td.bitDepth; });
        drop("alpha", t.alpha != td.alpha, "--alpha applies to .png images only",
             [&] { t.alpha = td.alpha; });
    }
}

}  // namespace splat::cli
