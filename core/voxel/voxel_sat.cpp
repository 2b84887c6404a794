#include "core/voxel/voxel_sat.h"

#include <algorithm>
#include <cmath>

namespace gilab {
namespace {

bool separates(const glm::vec3& axis, const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2,
               const glm::vec3& h) {
    const float p0 = glm::dot(axis, v0), p1 = glm::dot(axis, v1), p2 = glm::dot(axis, v2);
    const float r = glm::dot(h, glm::abs(axis));
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
}

}  // namespace

bool triangleBoxOverlap(const glm::vec3& center, const glm::vec3& h, const glm::vec3& a,
                        const glm::vec3& b, const glm::vec3& c) {
    const glm::vec3 v0 = a - center, v1 = b - center, v2 = c - center;
    const glm::vec3 lo = glm::min(v0, glm::min(v1, v2)), hi = glm::max(v0, glm::max(v1, v2));
    for (int i = 0; i < 3; ++i) {
        if (lo[i] > h[i] || hi[i] < -h[i]) return false;
    }
    const glm::vec3 edges[3] = {v1 - v0, v2 - v1, v0 - v2};
    const glm::vec3 n = glm::cross(edges[0], edges[1]);
    if (std::abs(glm::dot(n, v0)) > glm::dot(h, glm::abs(n))) return false;
    for (const glm::vec3& e : edges) {
        if (separates({0.0f, -e.z, e.y}, v0, v1, v2, h)) return false;
        if (separates({e.z, 0.0f, -e.x}, v0, v1, v2, h)) return false;
        if (separates({-e.y, e.x, 0.0f}, v0, v1, v2, h)) return false;
    }
    return true;
}

}  // namespace gilab
