// Generated Gaussian scenes (splat/gaussians.h): no 3DGS scene ships in a package here, so
// the tests, the popping analysis and the benchmark build their own.
#include <cmath>
#include <random>
#include <string>

#include "splat/error.h"
#include "splat/gaussians.h"

namespace splat {

namespace {

// SH degree-0 coefficient of a colour: 3DGS's colour is 0.5 + C0 * dc.
float dcOf(float colour) { return (colour - 0.5f) / 0.28209479177387814f; }

void add(GaussianScene& s, glm::vec3 mean, glm::vec3 scale, glm::vec4 q, float opacity,
         glm::vec3 colour) {
    s.means.push_back(mean);
    s.scales.push_back(scale);
    s.rotations.push_back(glm::normalize(q));
    s.opacities.push_back(opacity);
    const std::size_t k = std::size_t(s.shCount());
    const std::size_t at = s.sh.size();
    s.sh.resize(at + k * 3, 0.0f);
    for (int c = 0; c < 3; ++c) s.sh[at + std::size_t(c)] = dcOf(colour[c]);
}

GaussianScene pop() {
    GaussianScene s;
    s.shDegree = 0;
    add(s, {-0.6f, 0, 0}, glm::vec3(1.0f), {1, 0, 0, 0}, 0.8f, {1.0f, 0.1f, 0.1f});
    add(s, {0.6f, 0, 0}, glm::vec3(1.0f), {1, 0, 0, 0}, 0.8f, {0.1f, 0.2f, 1.0f});
    return s;
}

GaussianScene random(std::size_t n, unsigned seed) {
    GaussianScene s;
    s.shDegree = 3;
    s.means.reserve(n);
    s.scales.reserve(n);
    s.rotations.reserve(n);
    s.opacities.reserve(n);
    s.sh.reserve(n * 48);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::normal_distribution<float> g(0.0f, 1.0f);
    // Scales shrink with the count so that the cube's optical depth stays moderate.
    const float base = 0.25f / std::cbrt(float(n));
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 mean(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f);
        const glm::vec3 scale = base * glm::vec3(std::exp(0.5f * g(rng)), std::exp(0.5f * g(rng)),
                                                 std::exp(0.5f * g(rng)));
        const glm::vec4 q(g(rng), g(rng), g(rng), g(rng));
        add(s, mean, scale, glm::length(q) > 1e-6f ? q : glm::vec4(1, 0, 0, 0),
            0.2f + 0.75f * u(rng), {u(rng), u(rng), u(rng)});
        float* sh = s.sh.data() + i * 48;
        for (int j = 3; j < 48; ++j) sh[j] = 0.1f * g(rng);
    }
    return s;
}

}  // namespace

GaussianScene syntheticGaussians(const std::string& name) {
    GaussianScene s;
    if (name == "gaussians:pop") {
        s = pop();
    } else if (name.rfind("gaussians:random:", 0) == 0) {
        const std::string rest = name.substr(17);
        const std::size_t colon = rest.find(':');
        const std::string count = rest.substr(0, colon);
        const std::string seed = colon == std::string::npos ? "1" : rest.substr(colon + 1);
        auto number = [&](const std::string& t) {
            if (t.empty() || t.size() > 10 ||
                t.find_first_not_of("0123456789") != std::string::npos)
                throw Error("'" + name +
                            "': expected gaussians:random:N[:SEED] with whole numbers");
            return std::stoull(t);
        };
        const auto n = number(count);
        if (n < 1 || n > kMaxGaussians)
            throw Error("'" + name + "': N must be 1.." + std::to_string(kMaxGaussians));
        s = random(std::size_t(n), unsigned(number(seed)));
    } else {
        throw Error("unknown Gaussian scene '" + name +
                    "' (gaussians:pop, gaussians:random:N[:SEED])");
    }
    s.source = "generated (" + name + ")";
    return s;
}

}  // namespace splat
