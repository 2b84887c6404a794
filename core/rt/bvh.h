#pragma once
/**
 * A triangle BVH for the GPU ray tracer (shaders/common/rt_trace.glsl), built on the CPU with
 * Embree's BVH builder (rtcBuildBVH: binary SAH, high quality, spatial splits) and flattened
 * depth first into two arrays that are uploaded as storage buffers as they are:
 *
 *   BvhNode (32 B)      lower.xyz, rightOrFirst, upper.xyz, count
 *                       count == 0: interior; its left child is the next node, its right child
 *                                   node `rightOrFirst`
 *                       count  > 0: leaf of triangles [rightOrFirst, rightOrFirst + count)
 *   BvhTriangle (48 B)  v0.xyz, scene triangle id, e1.xyz, pad, e2.xyz, pad
 *                       p(b1, b2) = v0 + b1 e1 + b2 e2, the barycentrics Embree reports, so a
 *                       hit's (triangle id, b1, b2) reads the scene set's vertices directly
 *                       (interpolateVertex in shaders/common/scene.glsl)
 *
 * With spatial splits a triangle may sit in several leaves (a reference is duplicated).
 * Degenerate triangles (zero area: they can never be hit) are left out and counted. Rays need
 * tMin >= 0 (rt_trace.glsl). The intersection test is Moller-Trumbore, not watertight: a ray
 * through a shared edge can, rarely, pass between two triangles (docs/gpu_rays.md).
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace gilab {
struct Scene;
}

namespace gilab::rt {

struct BvhNode {
    glm::vec3 lower{0.0f};
    uint32_t rightOrFirst = 0;
    glm::vec3 upper{0.0f};
    uint32_t count = 0;
};
static_assert(sizeof(BvhNode) == 32);

struct BvhTriangle {
    glm::vec3 v0{0.0f};
    uint32_t triangle = 0;
    glm::vec3 e1{0.0f};
    float pad1 = 0.0f;
    glm::vec3 e2{0.0f};
    float pad2 = 0.0f;
};
static_assert(sizeof(BvhTriangle) == 48);

/** The deepest tree the GLSL traversal's stack holds (RT_STACK_SIZE in rt_trace.glsl). */
inline constexpr uint32_t kMaxBvhDepth = 64;

struct BvhStats {
    uint32_t nodes = 0;
    uint32_t leaves = 0;
    uint32_t depth = 0;         // root = 1
    uint32_t triangleRefs = 0;  // leaf entries (>= triangles with spatial splits)
    uint32_t triangles = 0;     // scene triangles with a non-zero area
    uint32_t degenerateDropped = 0;
    double buildMs = 0.0;
};

struct Bvh {
    std::vector<BvhNode> nodes;  // nodes[0] is the root (an empty leaf when nothing can hit)
    std::vector<BvhTriangle> triangles;
    BvhStats stats;
};

/** Builds the BVH of the scene's current triangles (world space). Throws gilab::Error if
 *  Embree fails or the tree is deeper than kMaxBvhDepth. */
Bvh buildBvh(const Scene& scene);

}  // namespace gilab::rt
