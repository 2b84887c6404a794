#pragma once
/**
 * The scene's world-space triangle mesh in Embree 3: one RTCDevice, one RTCScene (robust
 * flag, high-quality BVH) holding one triangle geometry, plus the per-triangle data the path
 * tracer shades with. Alpha-masked materials get intersection and occlusion filters that apply
 * the rasteriser's cutout rule (coverage = baseColorFactor.a x texture alpha < alphaCutoff:
 * the hit is ignored), so cut-out texels neither show nor shadow, for every ray type.
 *
 * Embree reports errors through a callback installed once per device; it records the message
 * and every API call site checks it and throws gilab::Error with Embree's text.
 */
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab::ref {

class TextureLookup;

/** One triangle: its three vertices as Embree sees them (the exact floats: the ray origins'
 *  error margins are measured against these, reference/spawn.h), p = p0 + b1 e1 + b2 e2 with
 *  Embree's barycentrics (b1, b2) = (u, v). It also carries its vertices' normals and uvs, so
 *  that shading a hit reads one aligned 128-byte record (two adjacent cache lines) instead of
 *  the triangle plus three scattered vertices (docs/reference.md, "Throughput"). */
struct alignas(128) MeshTriangle {
    glm::vec3 p0, p1, p2;
    glm::vec3 n;  // unit geometric normal of the counter-clockwise winding (cross(e1, e2))
    float area = 0.0f;
    uint32_t material = 0;
    uint32_t v[3] = {0, 0, 0};  // vertex indices
    glm::vec3 normal[3];        // the vertices' shading normals, as in Scene::vertices
    glm::vec2 uv[3];            // the vertices' texture coordinates

    /** Barycentric interpolation of the vertex uvs, (b1, b2) = Embree's (u, v). */
    glm::vec2 uvAt(float b1, float b2) const {
        return (1.0f - b1 - b2) * uv[0] + b1 * uv[1] + b2 * uv[2];
    }
    glm::vec3 e1() const { return p1 - p0; }
    glm::vec3 e2() const { return p2 - p0; }
};
static_assert(sizeof(MeshTriangle) == 128, "one triangle record is two cache lines");

struct RayHit {
    float t = 0.0f;
    uint32_t prim = 0;
    float u = 0.0f;  // barycentric of vertex 1
    float v = 0.0f;  // barycentric of vertex 2
};

class EmbreeScene {
public:
    EmbreeScene(const Scene& scene, const TextureLookup& textures);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    RTCDevice device() const { return m_device; }
    RTCScene handle() const { return m_scene; }
    /** Embree's version, e.g. "3.13.5" (RTC_DEVICE_PROPERTY_VERSION). */
    std::string version() const;
    /** Whether any triangle has a masked material (the filters are installed). */
    bool hasAlphaFilter() const { return m_hasAlphaFilter; }

    const MeshTriangle& triangle(uint32_t prim) const { return m_triangles[prim]; }
    size_t triangleCount() const { return m_triangles.size(); }

    /** Closest hit of o + t d, t in [tNear, tFar] (d need not be unit; t is in units of d). */
    bool intersect(const glm::vec3& o, const glm::vec3& d, float tNear, float tFar,
                   RayHit& hit) const;
    /** Whether anything (not cut out) lies on o + t d, t in [tNear, tFar]. */
    bool occluded(const glm::vec3& o, const glm::vec3& d, float tNear, float tFar) const;
    /** Closest hits of up to 16 rays (t in [0, tFar]) in one rtcIntersect16 call;
     *  hit[i].prim = ~0u on a miss. Lanes >= count are inactive. `coherent`: Embree's hint for
     *  rays of neighbouring pixels (camera rays). */
    void intersect16(int count, const glm::vec3* o, const glm::vec3* d, float tFar, RayHit* hit,
                     bool coherent = true) const;
    /** Occlusion of every ray in one rtcOccluded1M stream call (Embree regroups the rays);
     *  an occluded ray gets tfar = -inf. */
    void occludedStream(std::vector<RTCRay>& rays) const;
    /** rtcIntersect1M over `rays` (incoherent): the closest hits, in place. */
    void intersectStream(std::vector<RTCRayHit>& rays) const;
    /** Calls visit(prim) for every triangle whose bounding box the sphere (p, radius) touches
     *  (rtcPointQuery; a superset of the triangles within `radius`; the caller measures). */
    template <class Visit>
    void forEachNearby(const glm::vec3& p, float radius, Visit&& visit) const {
        RTCPointQuery query;
        query.x = p.x;
        query.y = p.y;
        query.z = p.z;
        query.time = 0.0f;
        query.radius = radius;
        RTCPointQueryContext context;
        rtcInitPointQueryContext(&context);
        auto callback = [](RTCPointQueryFunctionArguments* args) -> bool {
            (*static_cast<Visit*>(args->userPtr))(args->primID);
            return false;  // the query sphere is unchanged
        };
        rtcPointQuery(m_scene, &query, &context, callback, &visit);
    }

    /** Throws gilab::Error with Embree's message if the device reports an error. */
    void checkError(const char* what) const;

private:
    static void onError(void* user, RTCError code, const char* message);

    const Scene& m_sceneData;
    const TextureLookup& m_textures;
    std::vector<MeshTriangle> m_triangles;
    std::vector<uint8_t> m_masked;  // per triangle: material is alpha-masked
    bool m_hasAlphaFilter = false;
    RTCDevice m_device = nullptr;
    RTCScene m_scene = nullptr;

    mutable std::mutex m_errorMutex;
    mutable std::string m_lastError;

    friend struct AlphaFilter;
};

}  // namespace gilab::ref
