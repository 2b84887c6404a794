#pragma once
/**
 * Appends triangle geometry to a Scene in world space: the validation and clean-up shared by
 * the glTF loader and the procedural generators.
 */
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab {

/** One triangle primitive in its local space, as read from a file. */
struct PrimitiveData {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;  // empty: computed (area-weighted smooth)
    std::vector<glm::vec2> uvs;      // empty: all (0, 0)
    std::vector<uint32_t> indices;   // empty: non-indexed (0, 1, 2, ...)
};

/** Running totals the loader turns into warnings. */
struct MeshStats {
    size_t degenerateTriangles = 0;  // dropped: repeated index or zero area
    size_t recomputedNormals = 0;    // zero-length normals in the file, rebuilt from faces
};

/** Most vertices one scene may hold (32-bit indices; about 8.6 GB of vertices). */
constexpr size_t kMaxSceneVertices = size_t(1) << 28;

/**
 * Validates `prim` (finite attributes, matching counts, indices in range; errors name `what`),
 * transforms it by `toWorld` (normals by the inverse transpose; winding flipped when the
 * determinant is negative), drops degenerate triangles (a repeated index or zero area, counted
 * in `stats`, so nothing downstream divides by a zero area) and appends it with `material`.
 * A non-finite transform or world position, or more than kMaxSceneVertices vertices in the
 * scene, is an error.
 */
void appendPrimitive(Scene& scene, const PrimitiveData& prim, const glm::mat4& toWorld,
                     uint32_t material, const std::string& what, MeshStats& stats);

/**
 * Appends the planar convex quad a-b-c-d (in order around it) as two triangles with a flat
 * normal, wound counter-clockwise when seen from the side `facing` points to.
 */
void appendQuad(Scene& scene, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                const glm::vec3& d, const glm::vec3& facing, uint32_t material);

/**
 * One wall of a room: the interior rectangle origin + [0,1]^2 (u, v) facing `inward`, extruded
 * outwards (against `inward`) by `thickness` into a closed slab when thickness > 0. An optional
 * hole [u0, v0, u1, v1] (fractions of u and v) splits the wall into grid cells; every boundary
 * edge of the solid cells gets a side face, so the slab stays closed (each edge shared by exactly
 * two triangles).
 */
void appendWall(Scene& scene, const glm::vec3& origin, const glm::vec3& u, const glm::vec3& v,
                const glm::vec3& inward, float thickness, const std::optional<glm::vec4>& hole,
                uint32_t material);

/** Appends a double-sided Lambertian material (metallic 0, roughness 1); returns its index. */
uint32_t appendLambertianMaterial(Scene& scene, const std::string& name, const glm::vec3& albedo);

}  // namespace gilab
