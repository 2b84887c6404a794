#include "core/passes/shadow_cascades.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

namespace gilab {
namespace {

glm::vec3 upFor(const glm::vec3& dir) {
    return std::abs(dir.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
}

glm::mat4 lightView(const OrthoLightFrame& f) {
    return glm::lookAtRH(f.origin, f.origin + f.direction, upFor(f.direction));
}

/** Orthographic over [cx - hx, cx + hx] x [cy - hy, cy + hy] of the light view, y down,
 *  depth = 1 - distance / (2r) (reversed-Z). */
glm::mat4 orthoRect(const OrthoLightFrame& f, float cx, float cy, float hx, float hy) {
    glm::mat4 p(0.0f);
    p[0][0] = 1.0f / hx;
    p[3][0] = -cx / hx;
    p[1][1] = -1.0f / hy;
    p[3][1] = cy / hy;
    p[2][2] = 1.0f / (2.0f * f.radius);  // z_view = -distance
    p[3][2] = 1.0f;
    p[3][3] = 1.0f;
    return p * lightView(f);
}

struct Rect {
    glm::vec2 lo{std::numeric_limits<float>::max()};
    glm::vec2 hi{-std::numeric_limits<float>::max()};
    void extend(const glm::vec2& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
};

std::array<glm::vec3, 8> boxCorners(const Bounds& b) {
    std::array<glm::vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[size_t(i)] =
            glm::vec3(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z);
    return c;
}

}  // namespace

glm::mat4 orthoSceneViewProj(const OrthoLightFrame& frame) {
    return orthoRect(frame, 0.0f, 0.0f, frame.radius, frame.radius);
}

std::vector<ShadowCascade> fitShadowCascades(const Camera& camera, float aspect,
                                             const Bounds& sceneBox, const OrthoLightFrame& frame,
                                             const CascadeSettings& settings) {
    std::vector<ShadowCascade> out;
    if (settings.count == 0) return out;
    const glm::mat4 view = lightView(frame);
    auto toLight = [&](const glm::vec3& p) { return glm::vec2(view * glm::vec4(p, 1.0f)); };

    // The scene box's light-space rectangle; the whole-scene square if the box is unknown.
    Rect scene;
    if (sceneBox.valid()) {
        for (const glm::vec3& c : boxCorners(sceneBox))
            scene.extend(toLight(c));
    } else {
        scene.extend(glm::vec2(-frame.radius));
        scene.extend(glm::vec2(frame.radius));
    }

    // The camera's depth range, clipped to the box
    const glm::vec3 fwd = camera.forward(), right = camera.right(), up = camera.trueUp();
    float nearZ = camera.nearZ, farZ = camera.farZ;
    if (sceneBox.valid()) {
        float zMin = std::numeric_limits<float>::max(), zMax = -zMin;
        for (const glm::vec3& c : boxCorners(sceneBox)) {
            const float z = glm::dot(c - camera.position, fwd);
            zMin = std::min(zMin, z);
            zMax = std::max(zMax, z);
        }
        nearZ = std::max(nearZ, zMin);
        farZ = std::min(farZ, zMax);
    }
    const bool seen = farZ > nearZ && nearZ > 0.0f;

    const float tanY = std::tan(0.5f * camera.vfovRad), tanX = tanY * aspect;
    const uint32_t n = settings.count;
    auto splitDepth = [&](uint32_t i) {
        const float t = float(i) / float(n);
        const float logSplit = nearZ * std::pow(farZ / nearZ, t);
        const float uniform = nearZ + (farZ - nearZ) * t;
        return settings.split * logSplit + (1.0f - settings.split) * uniform;
    };
    const float usable =
        float(std::max(int(settings.resolution) - 2 * int(settings.marginTexels), 1));
    for (uint32_t i = 0; i < n; ++i) {
        Rect r = scene;
        ShadowCascade c;
        if (seen) {
            c.nearDepth = i == 0 ? nearZ : splitDepth(i);
            c.farDepth = i + 1 == n ? farZ : splitDepth(i + 1);
            Rect slice;
            for (float z : {c.nearDepth, c.farDepth})
                for (float sx : {-1.0f, 1.0f})
                    for (float sy : {-1.0f, 1.0f})
                        slice.extend(toLight(camera.position + fwd * z + right * (sx * z * tanX) +
                                             up * (sy * z * tanY)));
            const glm::vec2 lo = glm::max(slice.lo, scene.lo), hi = glm::min(slice.hi, scene.hi);
            if (lo.x < hi.x && lo.y < hi.y) r = Rect{lo, hi};
        }
        // Widen by the margin: texel = extent / (resolution - 2 margin)
        const glm::vec2 extent = glm::max(r.hi - r.lo, glm::vec2(1e-6f * frame.radius));
        glm::vec2 half = 0.5f * extent + float(settings.marginTexels) * extent / usable;
        glm::vec2 center = 0.5f * (r.lo + r.hi);
        if (settings.snap) {
            // Stable texels (issue 43): each half-extent rounded up to a quarter-octave step of
            // the light's radius, r 2^(-k/4), so a small camera move keeps the size, and the
            // centre moved to a whole texel, so the texel grid stays fixed in the light's space
            // and a fixed world point keeps its texel (shadow edges do not crawl). At most 19 %
            // coarser texels; the margin absorbs the half-texel shift.
            for (int a = 0; a < 2; ++a) {
                const float ratio = std::max(half[a], 1e-30f) / frame.radius;
                const float steps = std::floor(-4.0f * std::log2(ratio));
                half[a] = frame.radius * std::exp2(-steps / 4.0f);
                const float texel = 2.0f * half[a] / float(settings.resolution);
                center[a] = std::round(center[a] / texel) * texel;
            }
        }
        c.viewProj = orthoRect(frame, center.x, center.y, half.x, half.y);
        c.texel = 2.0f * std::max(half.x, half.y) / float(settings.resolution);
        out.push_back(c);
    }
    return out;
}

}  // namespace gilab
