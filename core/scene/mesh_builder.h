#pragma once
/**
 * Appends triangle geometry to a Scene in world space: the validation and clean-up shared by
 * the glTF loader and the procedural generators.
 */
#include <cstddef>
#include <cstdint>
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

/**
 * Validates `prim` (finite attributes, matching counts, indices in range; errors name `what`),
 * transforms it by `toWorld` (normals by the inverse transpose; winding flipped when the
 * determinant is negative), drops degenerate triangles and appends it with `material`.
 */
void appendPrimitive(Scene& scene, const PrimitiveData& prim, const glm::mat4& toWorld,
                     uint32_t material, const std::string& what, MeshStats& stats);

/**
 * Appends the planar convex quad a-b-c-d (in order around it) as two triangles with a flat
 * normal, wound counter-clockwise when seen from the side `facing` points to.
 */
void appendQuad(Scene& scene, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                const glm::vec3& d, const glm::vec3& facing, uint32_t material);

}  // namespace gilab
