#include "core/scene/emission.h"

#include <algorithm>
#include <cmath>

#include "core/image/color.h"

namespace gilab {
namespace {

/** Integer texel coordinate i (any integer) under the wrap mode, in [0, size). */
int wrapTexel(int i, int size, WrapMode mode) {
    switch (mode) {
        case WrapMode::ClampToEdge:
            return std::clamp(i, 0, size - 1);
        case WrapMode::MirroredRepeat: {
            const int period = 2 * size;
            int m = i % period;
            if (m < 0) m += period;
            return m < size ? m : period - 1 - m;
        }
        case WrapMode::Repeat:
            break;
    }
    int m = i % size;
    return m < 0 ? m + size : m;
}

glm::vec3 texel(const Texture& tex, int x, int y) {
    const uint8_t* t = &tex.rgba[(size_t(y) * size_t(tex.width) + size_t(x)) * 4];
    glm::vec3 c(t[0] / 255.0f, t[1] / 255.0f, t[2] / 255.0f);
    if (tex.colorSpace == ColorSpace::Srgb)
        c = glm::vec3(srgbToLinear(c.r), srgbToLinear(c.g), srgbToLinear(c.b));
    return c;
}

constexpr int kMinPieces = 8;    // k >= 8: 64 points at least
constexpr int kMaxPieces = 256;  // k <= 256: 65,536 points at most

}  // namespace

glm::vec3 bilinearLinear(const Texture& tex, glm::vec2 uv) {
    if (tex.width <= 0 || tex.height <= 0) return glm::vec3(1.0f);
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return texel(tex, 0, 0);
    const float x = uv.x * float(tex.width) - 0.5f, y = uv.y * float(tex.height) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const float ax = x - fx, ay = y - fy;
    const int x0 = int(fx), y0 = int(fy);
    const int xa = wrapTexel(x0, tex.width, tex.wrapU),
              xb = wrapTexel(x0 + 1, tex.width, tex.wrapU);
    const int ya = wrapTexel(y0, tex.height, tex.wrapV);
    const int yb = wrapTexel(y0 + 1, tex.height, tex.wrapV);
    const glm::vec3 top = glm::mix(texel(tex, xa, ya), texel(tex, xb, ya), ax);
    const glm::vec3 bottom = glm::mix(texel(tex, xa, yb), texel(tex, xb, yb), ax);
    return glm::mix(top, bottom, ay);
}

glm::vec3 meanTriangleEmission(const Scene& scene, size_t t) {
    const Material& m = scene.materials[scene.triangleMaterials[t]];
    if (m.emissiveTexture < 0 || size_t(m.emissiveTexture) >= scene.textures.size())
        return m.emissiveFactor;
    const Texture& tex = scene.textures[size_t(m.emissiveTexture)];
    if (tex.width <= 0 || tex.height <= 0) return m.emissiveFactor;
    const glm::vec2 uv0 = scene.vertices[scene.indices[3 * t]].uv;
    const glm::vec2 uv1 = scene.vertices[scene.indices[3 * t + 1]].uv;
    const glm::vec2 uv2 = scene.vertices[scene.indices[3 * t + 2]].uv;
    const glm::vec2 e1 = uv1 - uv0, e2 = uv2 - uv0;
    const double texels =
        0.5 * std::abs(double(e1.x) * e2.y - double(e1.y) * e2.x) * tex.width * tex.height;
    // k^2 pieces, about four per covered texel
    const double wanted = std::ceil(std::sqrt(4.0 * (std::isfinite(texels) ? texels : 0.0)));
    const int k = int(std::clamp(wanted, double(kMinPieces), double(kMaxPieces)));
    glm::dvec3 sum(0.0);
    auto at = [&](double b1, double b2) {
        const glm::vec2 uv = uv0 + float(b1) * e1 + float(b2) * e2;
        sum += glm::dvec3(bilinearLinear(tex, uv));
    };
    // Upward pieces (i, j), i + j <= k - 1, centroid ((i, j) + 1/3) / k; downward ones
    // (i + j <= k - 2) centroid ((i, j) + 2/3) / k: all of area 1 / k^2 of the triangle
    for (int i = 0; i < k; ++i)
        for (int j = 0; i + j < k; ++j) {
            at((i + 1.0 / 3.0) / k, (j + 1.0 / 3.0) / k);
            if (i + j + 2 <= k) at((i + 2.0 / 3.0) / k, (j + 2.0 / 3.0) / k);
        }
    return m.emissiveFactor * glm::vec3(sum / (double(k) * double(k)));
}

EmitterSummary computeEmitterSummary(const Scene& scene) {
    EmitterSummary out;
    constexpr double kPi = 3.14159265358979323846;
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        const Material& m = scene.materials[scene.triangleMaterials[t]];
        if (!m.isEmissive()) continue;
        const glm::dvec3 p0 = scene.vertices[scene.indices[3 * t]].position;
        const glm::dvec3 p1 = scene.vertices[scene.indices[3 * t + 1]].position;
        const glm::dvec3 p2 = scene.vertices[scene.indices[3 * t + 2]].position;
        const double area = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        ++out.triangleCount;
        out.areaM2 += area;
        // Lambertian: exitance pi Le per side (docs/conventions.md)
        out.powerW +=
            kPi * glm::dvec3(meanTriangleEmission(scene, t)) * area * (m.doubleSided ? 2.0 : 1.0);
    }
    return out;
}

}  // namespace gilab
