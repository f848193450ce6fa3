// The one enum <-> string table (see splat/settings.h).
#include "splat/settings.h"

#include <array>
#include <utility>

#include "splat/error.h"

namespace splat {

namespace {

template <class E, std::size_t N>
using Names = std::array<std::pair<E, const char*>, N>;

constexpr Names<RendererKind, 3> kRenderers{{{RendererKind::Axis, "axis"},
                                             {RendererKind::Sheet, "sheet"},
                                             {RendererKind::Reference, "reference"}}};
constexpr Names<RenderMode, 4> kModes{{{RenderMode::Dvr, "dvr"},
                                       {RenderMode::Mip, "mip"},
                                       {RenderMode::Xray, "xray"},
                                       {RenderMode::Iso, "iso"}}};
constexpr Names<Classification, 2> kClassifications{
    {{Classification::Pre, "pre"}, {Classification::Post, "post"}}};
constexpr Names<CompositeOrder, 2> kOrders{
    {{CompositeOrder::FrontToBack, "ftb"}, {CompositeOrder::BackToFront, "btf"}}};
constexpr Names<Projection, 2> kProjections{
    {{Projection::Orthographic, "ortho"}, {Projection::Perspective, "perspective"}}};
constexpr Names<Ewa, 3> kEwas{{{Ewa::Off, "off"}, {Ewa::On, "on"}, {Ewa::Auto, "auto"}}};
constexpr Names<Truth, 3> kTruths{
    {{Truth::Auto, "auto"}, {Truth::Point, "point"}, {Truth::Filtered, "filtered"}}};

template <class E, std::size_t N>
const char* nameOf(const Names<E, N>& names, E value) {
    for (const auto& [e, name] : names)
        if (e == value) return name;
    return "?";
}

template <class E, std::size_t N>
E parseName(const Names<E, N>& names, std::string_view text, const char* what) {
    std::string accepted;
    for (const auto& [e, name] : names) {
        if (text == name) return e;
        accepted += accepted.empty() ? "" : ", ";
        accepted += name;
    }
    throw Error("unknown " + std::string(what) + " '" + std::string(text) + "' (" + accepted + ")");
}

}  // namespace

const char* toString(RendererKind v) { return nameOf(kRenderers, v); }
const char* toString(RenderMode v) { return nameOf(kModes, v); }
const char* toString(Classification v) { return nameOf(kClassifications, v); }
const char* toString(CompositeOrder v) { return nameOf(kOrders, v); }
const char* toString(Projection v) { return nameOf(kProjections, v); }
const char* toString(Ewa v) { return nameOf(kEwas, v); }
Ewa parseEwa(std::string_view s) { return parseName(kEwas, s, "EWA setting"); }
const char* toString(Truth v) { return nameOf(kTruths, v); }
Truth parseTruth(std::string_view s) { return parseName(kTruths, s, "reference (truth)"); }
RendererKind parseRenderer(std::string_view s) { return parseName(kRenderers, s, "renderer"); }
RenderMode parseMode(std::string_view s) { return parseName(kModes, s, "mode"); }
Classification parseClassification(std::string_view s) {
    return parseName(kClassifications, s, "classification");
}
CompositeOrder parseOrder(std::string_view s) { return parseName(kOrders, s, "order"); }
Projection parseProjection(std::string_view s) { return parseName(kProjections, s, "projection"); }

bool Clipping::keeps(const glm::dvec3& x) const {
    if (cropBox)
        for (int a = 0; a < 3; ++a)
            if (x[a] < boxMin[a] || x[a] > boxMax[a]) return false;
    for (const ClipPlane& p : planes)
        if (glm::dot(x - p.point, p.normal) > 0.0) return false;
    return true;
}

}  // namespace splat
