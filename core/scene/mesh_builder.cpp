#include "core/scene/mesh_builder.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace gilab {

namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const glm::vec2& v) {
    return std::isfinite(v.x) && std::isfinite(v.y);
}

template <typename Vec>
void checkFinite(const std::vector<Vec>& values, const char* attribute, const std::string& what) {
    const size_t bad = size_t(
        std::count_if(values.begin(), values.end(), [](const Vec& v) { return !finite(v); }));
    if (bad > 0) {
        throw Error(what + ": " + std::to_string(bad) + " of " + std::to_string(values.size()) +
                    " " + attribute + " values are NaN or infinite");
    }
}

/**
 * Twice the triangle's area vector, or zero for a degenerate triangle: a repeated index, or an
 * area below 1e-10 of the longest edge squared (collinear to float precision).
 */
glm::dvec3 areaVector(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const glm::dvec3 e1 = glm::dvec3(b) - glm::dvec3(a);
    const glm::dvec3 e2 = glm::dvec3(c) - glm::dvec3(a);
    const glm::dvec3 e3 = glm::dvec3(c) - glm::dvec3(b);
    const glm::dvec3 n = glm::cross(e1, e2);
    const double maxEdge2 = std::max({glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(e3, e3)});
    const double area2 = glm::length(n);
    if (maxEdge2 == 0.0 || area2 <= 1e-10 * maxEdge2) return glm::dvec3(0.0);
    return n;
}

}  // namespace

void appendPrimitive(Scene& scene, const PrimitiveData& prim, const glm::mat4& toWorld,
                     uint32_t material, const std::string& what, MeshStats& stats) {
    // Validate counts, values and indices
    const size_t n = prim.positions.size();
    if (!prim.normals.empty() && prim.normals.size() != n) {
        throw Error(what + ": NORMAL count " + std::to_string(prim.normals.size()) +
                    " differs from POSITION count " + std::to_string(n));
    }
    if (!prim.uvs.empty() && prim.uvs.size() != n) {
        throw Error(what + ": TEXCOORD_0 count " + std::to_string(prim.uvs.size()) +
                    " differs from POSITION count " + std::to_string(n));
    }
    checkFinite(prim.positions, "POSITION", what);
    checkFinite(prim.normals, "NORMAL", what);
    checkFinite(prim.uvs, "TEXCOORD_0", what);

    std::vector<uint32_t> indices = prim.indices;
    if (indices.empty()) {
        indices.resize(n);
        for (size_t i = 0; i < n; ++i)
            indices[i] = uint32_t(i);
    }
    if (indices.size() % 3 != 0) {
        throw Error(what + ": " + std::to_string(indices.size()) +
                    " indices is not a multiple of 3");
    }
    const size_t outOfRange =
        size_t(std::count_if(indices.begin(), indices.end(), [n](uint32_t i) { return i >= n; }));
    if (outOfRange > 0) {
        throw Error(what + ": " + std::to_string(outOfRange) + " indices out of range (" +
                    std::to_string(n) + " vertices)");
    }

    if (n > kMaxSceneVertices - std::min(scene.vertices.size(), kMaxSceneVertices)) {
        throw Error(what + ": " + std::to_string(n) + " more vertices would exceed the limit of " +
                    std::to_string(kMaxSceneVertices) + " vertices per scene (the scene has " +
                    std::to_string(scene.vertices.size()) + ")");
    }
    for (int c = 0; c < 4; ++c) {
        if (!std::isfinite(toWorld[c].x + toWorld[c].y + toWorld[c].z + toWorld[c].w)) {
            throw Error(what + ": the node's world transform is not finite");
        }
    }

    // Transform to world space
    const glm::mat3 linear(toWorld);
    const bool flip = glm::determinant(linear) < 0.0f;
    const glm::mat3 normalMatrix = glm::transpose(glm::inverse(linear));
    std::vector<glm::vec3> positions(n);
    for (size_t i = 0; i < n; ++i)
        positions[i] = glm::vec3(toWorld * glm::vec4(prim.positions[i], 1.0f));
    const size_t overflowed = size_t(std::count_if(positions.begin(), positions.end(),
                                                   [](const glm::vec3& p) { return !finite(p); }));
    if (overflowed > 0) {
        throw Error(what + ": " + std::to_string(overflowed) + " of " + std::to_string(n) +
                    " POSITION values overflow a float in world space (node transform too large)");
    }

    // Keep non-degenerate triangles, accumulating area-weighted normals as we go
    std::vector<uint32_t> kept;
    kept.reserve(indices.size());
    std::vector<glm::dvec3> smooth(n, glm::dvec3(0.0));
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
        uint32_t i0 = indices[t], i1 = indices[t + 1], i2 = indices[t + 2];
        if (flip) std::swap(i1, i2);
        const glm::dvec3 area = (i0 == i1 || i1 == i2 || i0 == i2)
                                    ? glm::dvec3(0.0)
                                    : areaVector(positions[i0], positions[i1], positions[i2]);
        if (area == glm::dvec3(0.0)) {
            ++stats.degenerateTriangles;
            continue;
        }
        kept.insert(kept.end(), {i0, i1, i2});
        for (uint32_t i : {i0, i1, i2})
            smooth[i] += area;
    }

    // Normals: the file's (transformed) where usable, else the smooth face normal
    const uint32_t base = uint32_t(scene.vertices.size());
    scene.vertices.reserve(scene.vertices.size() + n);
    for (size_t i = 0; i < n; ++i) {
        glm::vec3 normal(0.0f);
        if (!prim.normals.empty()) {
            normal = normalMatrix * prim.normals[i];
            const float len = glm::length(normal);
            if (len > 0.0f && std::isfinite(len)) {
                normal /= len;
            } else {
                normal = glm::vec3(0.0f);
                ++stats.recomputedNormals;
            }
        }
        if (normal == glm::vec3(0.0f)) {
            const double len = glm::length(smooth[i]);
            normal = len > 0.0 ? glm::vec3(smooth[i] / len) : glm::vec3(0.0f, 1.0f, 0.0f);
        }
        Vertex v;
        v.position = positions[i];
        v.normal = normal;
        v.uv = prim.uvs.empty() ? glm::vec2(0.0f) : prim.uvs[i];
        scene.vertices.push_back(v);
    }
    for (uint32_t i : kept)
        scene.indices.push_back(base + i);
    scene.triangleMaterials.insert(scene.triangleMaterials.end(), kept.size() / 3, material);
}

void appendQuad(Scene& scene, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                const glm::vec3& d, const glm::vec3& facing, uint32_t material) {
    glm::vec3 normal = glm::normalize(glm::cross(b - a, c - a));
    glm::vec3 corners[4] = {a, b, c, d};
    if (glm::dot(normal, facing) < 0.0f) {
        std::swap(corners[1], corners[3]);
        normal = -normal;
    }
    const glm::vec2 uvs[4] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
    const uint32_t base = uint32_t(scene.vertices.size());
    for (int i = 0; i < 4; ++i)
        scene.vertices.push_back(Vertex{corners[i], normal, uvs[i]});
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
        scene.indices.push_back(base + i);
    scene.triangleMaterials.insert(scene.triangleMaterials.end(), 2, material);
}

void appendWall(Scene& scene, const glm::vec3& origin, const glm::vec3& u, const glm::vec3& v,
                const glm::vec3& inward, float thickness, const std::optional<glm::vec4>& hole,
                uint32_t material) {
    std::vector<float> us = {0.0f, 1.0f}, vs = {0.0f, 1.0f};
    if (hole) {
        us = {0.0f, hole->x, hole->z, 1.0f};
        vs = {0.0f, hole->y, hole->w, 1.0f};
        us.erase(std::unique(us.begin(), us.end()), us.end());
        vs.erase(std::unique(vs.begin(), vs.end()), vs.end());
    }
    const int nu = int(us.size()) - 1, nv = int(vs.size()) - 1;
    auto solid = [&](int i, int j) {
        if (i < 0 || j < 0 || i >= nu || j >= nv) return false;
        if (!hole) return true;
        const float cu = 0.5f * (us[size_t(i)] + us[size_t(i) + 1]);
        const float cv = 0.5f * (vs[size_t(j)] + vs[size_t(j) + 1]);
        return !(cu > hole->x && cu < hole->z && cv > hole->y && cv < hole->w);
    };
    const glm::vec3 out = -thickness * inward;
    auto at = [&](float a, float b) { return origin + a * u + b * v; };
    for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
            if (!solid(i, j)) continue;
            const float a0 = us[size_t(i)], a1 = us[size_t(i) + 1];
            const float b0 = vs[size_t(j)], b1 = vs[size_t(j) + 1];
            const glm::vec3 p00 = at(a0, b0), p10 = at(a1, b0), p11 = at(a1, b1), p01 = at(a0, b1);
            appendQuad(scene, p00, p10, p11, p01, inward, material);
            if (thickness <= 0.0f) continue;
            appendQuad(scene, p00 + out, p10 + out, p11 + out, p01 + out, -inward, material);
            // Side faces where the neighbouring cell is empty (outside or the hole)
            auto side = [&](const glm::vec3& p, const glm::vec3& q, const glm::vec3& facing) {
                appendQuad(scene, p, q, q + out, p + out, facing, material);
            };
            if (!solid(i - 1, j)) side(p00, p01, -u);
            if (!solid(i + 1, j)) side(p10, p11, u);
            if (!solid(i, j - 1)) side(p00, p10, -v);
            if (!solid(i, j + 1)) side(p01, p11, v);
        }
    }
}

uint32_t appendLambertianMaterial(Scene& scene, const std::string& name, const glm::vec3& albedo) {
    Material mat;
    mat.name = name;
    mat.baseColorFactor = glm::vec4(albedo, 1.0f);
    mat.metallic = 0.0f;
    mat.roughness = 1.0f;
    mat.doubleSided = true;
    scene.materials.push_back(mat);
    return uint32_t(scene.materials.size() - 1);
}

}  // namespace gilab
