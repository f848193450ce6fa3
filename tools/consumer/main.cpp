// An outside program linked against the installed splat package: renders the X-ray of a
// 16^3 constant cube (value 1, spacing 1 mm, in a 20^3 volume of 0: the faces give the
// background value 0) held in a caller-owned array and, after a round trip through a NIfTI
// file, loaded with loadVolume. Through the centre the line
// integral of the reconstructed field is the cube's length, 16 (to the kernel's
// partition-of-unity ripple). Prints both centre pixels; exits 1 unless both are 16 to 1%.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <splat/render.h>
#include <splat/scene.h>
#include <splat/version.h>
#include <splat/volume_io.h>
#include <vector>

int main(int argc, char** argv) {
    const std::filesystem::path dir = argc > 1 ? argv[1] : std::filesystem::temp_directory_path();
    // A caller-owned array of samples, x fastest.
    const int n = 20;
    std::vector<float> samples(n * n * n, 0.0f);
    for (int k = 2; k < 18; ++k)
        for (int j = 2; j < 18; ++j)
            for (int i = 2; i < 18; ++i) samples[(k * n + j) * n + i] = 1.0f;
    splat::Volume cube = splat::makeVolume(glm::ivec3(n), glm::dvec3(1.0), "caller array");
    cube.data.assign(samples.begin(), samples.end());

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

    std::printf("splat %s: centre pixel %.5f (array), %.5f (NIfTI)\n", splat::kVersion, a, b);
    return std::abs(a - 16.0f) < 0.16f && std::abs(b - 16.0f) < 0.16f ? 0 : 1;
}
