#include "reference/embree_scene.h"

#include <cmath>
#include <limits>

#include "core/util/error.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {

/** The filter function of masked geometry: drops hits whose texel is cut out. */
struct AlphaFilter {
    static void apply(const RTCFilterFunctionNArguments* args) {
        const auto* self = static_cast<const EmbreeScene*>(args->geometryUserPtr);
        for (unsigned i = 0; i < args->N; ++i) {
            if (args->valid[i] != -1) continue;
            const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
            if (!self->m_masked[prim]) continue;
            const float b1 = RTCHitN_u(args->hit, args->N, i);
            const float b2 = RTCHitN_v(args->hit, args->N, i);
            const MeshTriangle& tri = self->m_triangles[prim];
            const glm::vec2 uv = tri.uvAt(b1, b2);
            if (isCutOut(self->m_sceneData.materials[tri.material], self->m_textures, uv))
                args->valid[i] = 0;
        }
    }
};

void EmbreeScene::onError(void* user, RTCError code, const char* message) {
    auto* self = static_cast<EmbreeScene*>(user);
    std::lock_guard<std::mutex> lock(self->m_errorMutex);
    self->m_lastError = "error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

void EmbreeScene::checkError(const char* what) const {
    const RTCError code = rtcGetDeviceError(m_device);
    std::lock_guard<std::mutex> lock(m_errorMutex);
    if (code == RTC_ERROR_NONE && m_lastError.empty()) return;
    std::string message = m_lastError.empty() ? "error " + std::to_string(int(code)) : m_lastError;
    m_lastError.clear();
    throw Error(std::string("Embree: ") + what + ": " + message);
}

EmbreeScene::EmbreeScene(const Scene& scene, const TextureLookup& textures)
    : m_sceneData(scene), m_textures(textures) {
    const size_t triCount = scene.triangleCount();
    if (triCount > size_t(std::numeric_limits<int32_t>::max()))
        throw Error("scene '" + scene.name + "': too many triangles for Embree");

    // Per-triangle data (world space, counter-clockwise geometric normal)
    m_triangles.resize(triCount);
    m_masked.assign(triCount, 0);
    for (size_t t = 0; t < triCount; ++t) {
        MeshTriangle& tri = m_triangles[t];
        for (int k = 0; k < 3; ++k) {
            tri.v[k] = scene.indices[3 * t + size_t(k)];
            if (tri.v[k] >= scene.vertices.size())
                throw Error("scene '" + scene.name + "': triangle " + std::to_string(t) +
                            " indexes vertex " + std::to_string(tri.v[k]) + " of " +
                            std::to_string(scene.vertices.size()));
            tri.normal[k] = scene.vertices[tri.v[k]].normal;
            tri.uv[k] = scene.vertices[tri.v[k]].uv;
        }
        tri.p0 = scene.vertices[tri.v[0]].position;
        tri.p1 = scene.vertices[tri.v[1]].position;
        tri.p2 = scene.vertices[tri.v[2]].position;
        const glm::vec3 c = glm::cross(tri.e1(), tri.e2());
        const float len = glm::length(c);
        tri.area = 0.5f * len;
        tri.n = len > 0.0f ? c / len : glm::vec3(0.0f);
        tri.material = t < scene.triangleMaterials.size() ? scene.triangleMaterials[t] : ~0u;
        if (tri.material >= scene.materials.size())
            throw Error("scene '" + scene.name + "': triangle " + std::to_string(t) +
                        " has no valid material");
        if (scene.materials[tri.material].alphaMode != AlphaMode::Opaque) {
            m_masked[t] = 1;
            m_hasAlphaFilter = true;
        }
    }

    m_device = rtcNewDevice("verbose=0");
    if (!m_device) {
        throw Error("Embree: rtcNewDevice failed (error " +
                    std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    }
    rtcSetDeviceErrorFunction(m_device, &EmbreeScene::onError, this);
    if (m_hasAlphaFilter &&
        !rtcGetDeviceProperty(m_device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED))
        throw Error("Embree was built without filter functions; alpha masks need them");

    m_scene = rtcNewScene(m_device);
    rtcSetSceneFlags(m_scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(m_scene, RTC_BUILD_QUALITY_HIGH);
    checkError("creating the scene");

    if (triCount > 0) {
        RTCGeometry geom = rtcNewGeometry(m_device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* positions = static_cast<float*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                    3 * sizeof(float), scene.vertices.size()));
        auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
            geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triCount));
        checkError("allocating geometry buffers");
        for (size_t i = 0; i < scene.vertices.size(); ++i) {
            const glm::vec3& p = scene.vertices[i].position;
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                throw Error("scene '" + scene.name + "': vertex " + std::to_string(i) +
                            " has a non-finite position");
            positions[3 * i + 0] = p.x;
            positions[3 * i + 1] = p.y;
            positions[3 * i + 2] = p.z;
        }
        for (size_t i = 0; i < 3 * triCount; ++i)
            indices[i] = scene.indices[i];
        rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
        if (m_hasAlphaFilter) {
            rtcSetGeometryUserData(geom, this);
            rtcSetGeometryIntersectFilterFunction(geom, &AlphaFilter::apply);
            rtcSetGeometryOccludedFilterFunction(geom, &AlphaFilter::apply);
        }
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(m_scene, geom, 0);
        rtcReleaseGeometry(geom);
        checkError("building the triangle geometry");
    }
    rtcCommitScene(m_scene);
    checkError("building the BVH");
}

EmbreeScene::~EmbreeScene() {
    if (m_scene) rtcReleaseScene(m_scene);
    if (m_device) rtcReleaseDevice(m_device);
}

std::string EmbreeScene::version() const {
    const auto major = rtcGetDeviceProperty(m_device, RTC_DEVICE_PROPERTY_VERSION_MAJOR);
    const auto minor = rtcGetDeviceProperty(m_device, RTC_DEVICE_PROPERTY_VERSION_MINOR);
    const auto patch = rtcGetDeviceProperty(m_device, RTC_DEVICE_PROPERTY_VERSION_PATCH);
    return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
}

bool EmbreeScene::intersect(const glm::vec3& o, const glm::vec3& d, float tNear, float tFar,
                            RayHit& hit) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = o.x;
    rh.ray.org_y = o.y;
    rh.ray.org_z = o.z;
    rh.ray.tnear = tNear;
    rh.ray.dir_x = d.x;
    rh.ray.dir_y = d.y;
    rh.ray.dir_z = d.z;
    rh.ray.time = 0.0f;
    rh.ray.tfar = tFar;
    rh.ray.mask = ~0u;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(m_scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    hit.prim = rh.hit.primID;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    return true;
}

bool EmbreeScene::occluded(const glm::vec3& o, const glm::vec3& d, float tNear, float tFar) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray;
    ray.org_x = o.x;
    ray.org_y = o.y;
    ray.org_z = o.z;
    ray.tnear = tNear;
    ray.dir_x = d.x;
    ray.dir_y = d.y;
    ray.dir_z = d.z;
    ray.time = 0.0f;
    ray.tfar = tFar;
    ray.mask = ~0u;
    ray.id = 0;
    ray.flags = 0;
    rtcOccluded1(m_scene, &context, &ray);
    return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

void EmbreeScene::intersect16(int count, const glm::vec3* o, const glm::vec3* d, float tFar,
                              RayHit* hit, bool coherent) const {
    alignas(64) int valid[16];
    alignas(64) RTCRayHit16 rh;
    for (int i = 0; i < 16; ++i) {
        const bool active = i < count;
        valid[i] = active ? -1 : 0;
        const glm::vec3 oi = active ? o[i] : glm::vec3(0.0f);
        const glm::vec3 di = active ? d[i] : glm::vec3(0.0f, 0.0f, 1.0f);
        rh.ray.org_x[i] = oi.x;
        rh.ray.org_y[i] = oi.y;
        rh.ray.org_z[i] = oi.z;
        rh.ray.tnear[i] = 0.0f;
        rh.ray.dir_x[i] = di.x;
        rh.ray.dir_y[i] = di.y;
        rh.ray.dir_z[i] = di.z;
        rh.ray.time[i] = 0.0f;
        rh.ray.tfar[i] = tFar;
        rh.ray.mask[i] = ~0u;
        rh.ray.id[i] = unsigned(i);
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags =
        coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcIntersect16(valid, m_scene, &context, &rh);
    for (int i = 0; i < count; ++i) {
        if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
            hit[i].prim = ~0u;
            continue;
        }
        hit[i].t = rh.ray.tfar[i];
        hit[i].prim = rh.hit.primID[i];
        hit[i].u = rh.hit.u[i];
        hit[i].v = rh.hit.v[i];
    }
}

void EmbreeScene::intersectStream(std::vector<RTCRayHit>& rays) const {
    if (rays.empty()) return;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcIntersect1M(m_scene, &context, rays.data(), unsigned(rays.size()), sizeof(RTCRayHit));
}

void EmbreeScene::occludedStream(std::vector<RTCRay>& rays) const {
    if (rays.empty()) return;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcOccluded1M(m_scene, &context, rays.data(), unsigned(rays.size()), sizeof(RTCRay));
}

}  // namespace gilab::ref
