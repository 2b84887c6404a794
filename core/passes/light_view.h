#pragma once
/**
 * View-projections of a light's view, shared by the shadow maps (core/passes/shadow_maps.cpp)
 * and every technique that rasterises from a light (light-view maps). All are
 * reversed-Z with an infinite far plane: depth = near / distance along the view axis.
 */
#include <glm/glm.hpp>

namespace gilab {

/** Vulkan cube face axes (spec "Cube Map Face Selection"): s, t and the major axis m. */
struct CubeFace {
    glm::vec3 s, t, m;
};
inline constexpr CubeFace kCubeFaces[6] = {
    {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}}, {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}},
    {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},   {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},
    {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
};

/**
 * Pinhole view from `eye` with forward f and unit image-plane axes x, y: clip = (x.q / tanHalf,
 * y.q / tanHalf, near, f.q) with q = p - eye, so ndc = image-plane coordinates at unit distance /
 * tanHalf. A cube face is pinholeViewProj(eye, m, s, t, 1, near): framebuffer (x, y) / size is
 * exactly the face's (s, t).
 */
inline glm::mat4 pinholeViewProj(const glm::vec3& eye, const glm::vec3& f, const glm::vec3& x,
                                 const glm::vec3& y, float tanHalf, float nearZ) {
    glm::mat4 m(0.0f);
    for (int i = 0; i < 3; ++i) {
        m[i][0] = x[i] / tanHalf;
        m[i][1] = y[i] / tanHalf;
        m[i][3] = f[i];
    }
    m[3][0] = -glm::dot(x, eye) / tanHalf;
    m[3][1] = -glm::dot(y, eye) / tanHalf;
    m[3][2] = nearZ;
    m[3][3] = -glm::dot(f, eye);
    return m;
}

}  // namespace gilab
