// An outside program linked against the installed splat package, as research code would use
// it. It renders the X-ray of a 16^3 constant cube (value 1, spacing 1 mm, in a
// 20^3 volume of 0) whose samples live in a caller-owned uint16 array, borrowed without a
// copy (Volume::borrow, scale 1/1000) and, after a round trip through a NIfTI file, loaded
// with loadVolume. Through the centre the line integral of the reconstructed field is the
// cube's length, 16 (to the kernel's partition-of-unity ripple). Then it runs the popping
// analyzer over a custom path of free (eye/look-at) cameras, and cancels a frame from
// inside. Exits 1 unless both centre pixels are 16 to 1%, the analysis measured every
// interval and the frame stopped on the cancel.
#include <splat/popping.h>
#include <splat/render.h>
#include <splat/scene.h>
#include <splat/version.h>
#include <splat/volume_io.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

int main(int argc, char** argv) {
    const std::filesystem::path dir = argc > 1 ? argv[1] : std::filesystem::temp_directory_path();
    // A caller-owned array of samples, x fastest: 1000 stands for 1.0.
    const int n = 20;
    auto samples = std::make_shared<std::vector<std::uint16_t>>(n * n * n, 0);
    for (int k = 2; k < 18; ++k)
        for (int j = 2; j < 18; ++j)
            for (int i = 2; i < 18; ++i) (*samples)[(k * n + j) * n + i] = 1000;
    const splat::Volume cube =
        splat::Volume::borrow(samples->data(), splat::SampleType::UInt16, glm::ivec3(n),
                              glm::dvec3(1.0), glm::dvec3(0.0), samples, 1.0 / 1000.0);

    splat::RenderSettings s;
    s.mode = splat::RenderMode::Xray;
    s.camera.width = s.camera.height = 41;  // an odd size: a pixel centre on the axis
    s.camera.pixelSize = 1.0;
    const splat::Scene fromArray(cube, s);
    const float a = fromArray.render(splat::RendererKind::Axis, s.camera).at(20, 20).r;

    const std::string file = (dir / "splat_consumer_cube.nii.gz").string();
    splat::saveNifti(file, cube);
    const splat::Volume loaded = splat::loadVolume(file);
    std::filesystem::remove(file);
    const float b = splat::render(loaded, s).at(20, 20).r;

    // A custom camera path: five free cameras circling the cube, looking at its centre.
    std::vector<splat::CameraParams> path;
    for (int v = 0; v < 5; ++v) {
        splat::CameraParams c = s.camera;
        c.lookAtSet = true;
        c.lookAt = cube.center();
        c.eye = cube.center() + glm::dvec3(60 * std::sin(0.1 * v), -60 * std::cos(0.1 * v), 10);
        path.push_back(c);
    }
    splat::PoppingOptions o;
    o.renderers = {splat::RendererKind::Sheet, splat::RendererKind::Reference};
    o.refine = 2;
    o.flip = false;
    const splat::PoppingResult popping = splat::analyzePopping(fromArray, path, o);
    const bool analysed =
        popping.pathViews == 5 && popping.series.size() == 2 && popping.series[0].J.size() == 4;

    // Cancel inside a frame: the first tile's report says stop.
    int calls = 0;
    splat::RenderSettings cancelled = fromArray.settings();
    cancelled.renderer = splat::RendererKind::Sheet;
    cancelled.progress = [&](std::size_t, std::size_t, const std::string&) {
        ++calls;
        return false;
    };
    bool stopped = false;
    try {
        fromArray.render(cancelled);
    } catch (const splat::Cancelled&) {
        stopped = true;
    }

    std::printf(
        "splat %s: centre pixel %.5f (borrowed uint16 array), %.5f (NIfTI); camera path "
        "of %zu views analysed (%zu events); cancelled after %d progress call(s)\n",
        splat::kVersion, a, b, popping.angles.size(), popping.events.size(), calls);
    const bool pixels = std::abs(a - 16.0f) < 0.16f && std::abs(b - 16.0f) < 0.16f;
    return pixels && analysed && stopped && calls >= 1 ? 0 : 1;
}
