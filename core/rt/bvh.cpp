#include "bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include <embree3/rtcore.h>

#include "core/scene/scene.h"
#include "core/util/error.h"

namespace gilab::rt {
namespace {

// Temporary tree in Embree's thread-local build memory (freed with the RTCBVH).
struct TmpNode {
    bool leaf = false;
};
struct TmpInterior : TmpNode {
    TmpNode* child[2] = {nullptr, nullptr};
    RTCBounds bounds[2]{};
};
struct TmpLeaf : TmpNode {
    uint32_t count = 0;
    uint32_t prims[1];  // `count` entries (allocated past the struct)
};

struct BuildInput {
    const std::vector<glm::vec3>* v0;
    const std::vector<glm::vec3>* v1;
    const std::vector<glm::vec3>* v2;
};

void* createNode(RTCThreadLocalAllocator alloc, unsigned int numChildren, void*) {
    if (numChildren != 2) return nullptr;  // maxBranchingFactor = 2
    void* mem = rtcThreadLocalAlloc(alloc, sizeof(TmpInterior), 16);
    return new (mem) TmpInterior();
}

void setNodeChildren(void* node, void** children, unsigned int numChildren, void*) {
    auto* n = static_cast<TmpInterior*>(node);
    for (unsigned i = 0; i < numChildren && i < 2; ++i)
        n->child[i] = static_cast<TmpNode*>(children[i]);
}

void setNodeBounds(void* node, const RTCBounds** bounds, unsigned int numChildren, void*) {
    auto* n = static_cast<TmpInterior*>(node);
    for (unsigned i = 0; i < numChildren && i < 2; ++i)
        n->bounds[i] = *bounds[i];
}

void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t numPrims,
                 void*) {
    const size_t bytes = sizeof(TmpLeaf) + sizeof(uint32_t) * (numPrims > 0 ? numPrims - 1 : 0);
    void* mem = rtcThreadLocalAlloc(alloc, bytes, 16);
    auto* leaf = new (mem) TmpLeaf();
    leaf->leaf = true;
    leaf->count = uint32_t(numPrims);
    for (size_t i = 0; i < numPrims; ++i)
        leaf->prims[i] = prims[i].primID;
    return leaf;
}

/** Spatial split: the bounds of the triangle clipped to each side of the plane
 *  x[dimension] = position, each intersected with the reference's current bounds. */
void splitPrimitive(const RTCBuildPrimitive* prim, unsigned int dim, float pos, RTCBounds* left,
                    RTCBounds* right, void* user) {
    const BuildInput& in = *static_cast<const BuildInput*>(user);
    const glm::vec3 p[3] = {(*in.v0)[prim->primID], (*in.v1)[prim->primID], (*in.v2)[prim->primID]};
    glm::vec3 lo[2] = {glm::vec3(INFINITY), glm::vec3(INFINITY)};
    glm::vec3 hi[2] = {glm::vec3(-INFINITY), glm::vec3(-INFINITY)};
    auto add = [&](int side, const glm::vec3& q) {
        lo[side] = glm::min(lo[side], q);
        hi[side] = glm::max(hi[side], q);
    };
    for (int i = 0; i < 3; ++i) {
        const glm::vec3& a = p[i];
        const glm::vec3& b = p[(i + 1) % 3];
        if (a[dim] <= pos) add(0, a);
        if (a[dim] >= pos) add(1, a);
        if ((a[dim] < pos && b[dim] > pos) || (a[dim] > pos && b[dim] < pos)) {
            const float t = (pos - a[dim]) / (b[dim] - a[dim]);
            glm::vec3 q = a + t * (b - a);
            q[dim] = pos;
            add(0, q);
            add(1, q);
        }
    }
    const glm::vec3 plo(prim->lower_x, prim->lower_y, prim->lower_z);
    const glm::vec3 phi(prim->upper_x, prim->upper_y, prim->upper_z);
    RTCBounds* out[2] = {left, right};
    for (int s = 0; s < 2; ++s) {
        glm::vec3 l = glm::max(lo[s], plo), h = glm::min(hi[s], phi);
        if (s == 0)
            h[dim] = std::min(h[dim], pos);
        else
            l[dim] = std::max(l[dim], pos);
        if (!(l.x <= h.x && l.y <= h.y && l.z <= h.z)) l = h = glm::vec3(pos);  // empty side
        out[s]->lower_x = l.x, out[s]->lower_y = l.y, out[s]->lower_z = l.z;
        out[s]->upper_x = h.x, out[s]->upper_y = h.y, out[s]->upper_z = h.z;
        out[s]->align0 = out[s]->align1 = 0.0f;
    }
}

struct Flattener {
    const std::vector<BvhTriangle>& source;  // indexed by build primitive id
    Bvh& out;

    void visit(const TmpNode* node, const RTCBounds& b, uint32_t depth) {
        if (depth > kMaxBvhDepth)
            throw Error("BVH: deeper than " + std::to_string(kMaxBvhDepth) +
                        " levels (the GPU traversal stack); the scene's triangles are too "
                        "many or too degenerate for it");
        out.stats.depth = std::max(out.stats.depth, depth);
        const uint32_t index = uint32_t(out.nodes.size());
        out.nodes.emplace_back();
        out.nodes[index].lower = glm::vec3(b.lower_x, b.lower_y, b.lower_z);
        out.nodes[index].upper = glm::vec3(b.upper_x, b.upper_y, b.upper_z);
        if (node->leaf) {
            const auto* leaf = static_cast<const TmpLeaf*>(node);
            out.nodes[index].rightOrFirst = uint32_t(out.triangles.size());
            out.nodes[index].count = leaf->count;
            for (uint32_t i = 0; i < leaf->count; ++i)
                out.triangles.push_back(source[leaf->prims[i]]);
            ++out.stats.leaves;
            return;
        }
        const auto* interior = static_cast<const TmpInterior*>(node);
        visit(interior->child[0], interior->bounds[0], depth + 1);
        out.nodes[index].rightOrFirst = uint32_t(out.nodes.size());
        visit(interior->child[1], interior->bounds[1], depth + 1);
    }
};

}  // namespace

Bvh buildBvh(const Scene& scene) {
    const auto start = std::chrono::steady_clock::now();
    Bvh bvh;
    const size_t triangleCount = scene.indices.size() / 3;
    std::vector<BvhTriangle> tris;
    std::vector<glm::vec3> v0, v1, v2;
    std::vector<RTCBuildPrimitive> prims;
    tris.reserve(triangleCount);
    prims.reserve(2 * triangleCount + 1);  // spatial splits need room for extra references
    RTCBounds all{INFINITY, INFINITY, INFINITY, 0.0f, -INFINITY, -INFINITY, -INFINITY, 0.0f};
    for (size_t t = 0; t < triangleCount; ++t) {
        const glm::vec3 a = scene.vertices[scene.indices[3 * t]].position;
        const glm::vec3 b = scene.vertices[scene.indices[3 * t + 1]].position;
        const glm::vec3 c = scene.vertices[scene.indices[3 * t + 2]].position;
        const glm::vec3 e1 = b - a, e2 = c - a;
        const float area2 = glm::length(glm::cross(e1, e2));
        if (!(area2 > 0.0f) || !std::isfinite(area2)) {
            ++bvh.stats.degenerateDropped;
            continue;
        }
        BvhTriangle tri;
        tri.v0 = a;
        tri.triangle = uint32_t(t);
        tri.e1 = e1;
        tri.e2 = e2;
        const glm::vec3 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
        RTCBuildPrimitive p{};
        p.lower_x = lo.x, p.lower_y = lo.y, p.lower_z = lo.z;
        p.upper_x = hi.x, p.upper_y = hi.y, p.upper_z = hi.z;
        p.geomID = 0;
        p.primID = unsigned(tris.size());
        prims.push_back(p);
        tris.push_back(tri);
        v0.push_back(a), v1.push_back(b), v2.push_back(c);
        all.lower_x = std::min(all.lower_x, lo.x), all.lower_y = std::min(all.lower_y, lo.y);
        all.lower_z = std::min(all.lower_z, lo.z), all.upper_x = std::max(all.upper_x, hi.x);
        all.upper_y = std::max(all.upper_y, hi.y), all.upper_z = std::max(all.upper_z, hi.z);
    }
    bvh.stats.triangles = uint32_t(tris.size());

    if (tris.empty()) {
        // A leaf (count > 0) holding one triangle that never hits (zero edges: det == 0), so
        // the traversal never reads a child past the array and every ray misses
        bvh.nodes.emplace_back();
        bvh.nodes[0].rightOrFirst = 0;
        bvh.nodes[0].count = 1;
        BvhTriangle never;
        never.triangle = 0xffffffffu;
        bvh.triangles.push_back(never);
        bvh.stats.nodes = 1;
        bvh.stats.leaves = 1;
        bvh.stats.depth = 1;
        bvh.stats.buildMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        return bvh;
    }

    RTCDevice device = rtcNewDevice("verbose=0");
    if (!device)
        throw Error("BVH: rtcNewDevice failed (error " +
                    std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    RTCBVH handle = rtcNewBVH(device);
    BuildInput input{&v0, &v1, &v2};
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.byteSize = sizeof(args);
    args.buildFlags = RTC_BUILD_FLAG_NONE;
    args.buildQuality = RTC_BUILD_QUALITY_HIGH;
    args.maxBranchingFactor = 2;
    args.maxDepth = kMaxBvhDepth - 4;
    args.sahBlockSize = 1;
    args.minLeafSize = 1;
    args.maxLeafSize = 4;
    args.traversalCost = 1.0f;
    args.intersectionCost = 1.0f;
    args.bvh = handle;
    args.primitives = prims.data();
    args.primitiveCount = prims.size();
    args.primitiveArrayCapacity = prims.capacity();
    args.createNode = createNode;
    args.setNodeChildren = setNodeChildren;
    args.setNodeBounds = setNodeBounds;
    args.createLeaf = createLeaf;
    args.splitPrimitive = splitPrimitive;
    args.buildProgress = nullptr;
    args.userPtr = &input;
    auto* root = static_cast<TmpNode*>(rtcBuildBVH(&args));
    const RTCError error = rtcGetDeviceError(device);
    try {
        if (!root || error != RTC_ERROR_NONE)
            throw Error("BVH: rtcBuildBVH failed (Embree error " + std::to_string(int(error)) +
                        ")");
        bvh.nodes.reserve(2 * tris.size());
        bvh.triangles.reserve(prims.size());
        Flattener{tris, bvh}.visit(root, all, 1);
    } catch (...) {
        rtcReleaseBVH(handle);
        rtcReleaseDevice(device);
        throw;
    }
    rtcReleaseBVH(handle);
    rtcReleaseDevice(device);
    bvh.stats.nodes = uint32_t(bvh.nodes.size());
    bvh.stats.triangleRefs = uint32_t(bvh.triangles.size());
    bvh.stats.buildMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace gilab::rt
