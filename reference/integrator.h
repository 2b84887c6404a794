#pragma once
/**
 * The estimator of the reference: unidirectional path tracing with next-event estimation,
 * split exactly by bounce (docs/reference.md).
 *
 * A path's surface vertices are numbered k = 1 (the camera ray's hit), 2, ... Light arriving
 * at vertex k and scattered along the path to the eye goes to one layer: k = 1 direct,
 * 2 bounce1, 3 bounce2, >= 4 bounce3plus; emission seen by the camera goes to `emission`.
 * Vertex k receives light by NEE (punctual lights always; emissive triangles unless BsdfOnly)
 * and by its BSDF-sampled ray hitting an emitter at vertex k + 1 (unless NeeOnly); under Mis
 * the two emitter estimates are weighted by the power heuristic (Veach 1997 §9.2).
 * maxBounces = B: light arriving at vertices k <= B + 1 only.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/camera.h"
#include "reference/path_tracer.h"

namespace gilab::ref {

class LightSampler;
class Sampler;
class TextureLookup;
struct RayHit;

/** Radiance of one camera path per layer (index = Layer); Full = the sum of the others. */
struct PathRadiance {
    glm::vec3 L[kLayerCount];
};

struct PathCounters {
    uint64_t cameraRays = 0;
    uint64_t bounceRays = 0;
    uint64_t shadowRays = 0;
};

class Integrator {
public:
    Integrator(const Scene& scene, const ReferenceSettings& settings, const EmbreeScene& mesh,
               const LightSampler& lights, const TextureLookup& textures);

    /**
     * Traces one path from the camera ray `ray` (unit direction). `cameraHit`: the camera
     * ray's closest hit when already traced (packets; prim == ~0u for a miss), or nullptr to
     * trace it here. `sink` receives every ray traced (benchmarks), or nullptr.
     */
    void radiance(const Ray& ray, const RayHit* cameraHit, Sampler& sampler, PathRadiance& out,
                  PathCounters& counters, std::vector<RecordedRay>* sink) const;

private:
    const Scene& m_scene;
    const ReferenceSettings& m_settings;
    const EmbreeScene& m_mesh;
    const LightSampler& m_lights;
    const TextureLookup& m_textures;
    float m_offsetScale = 1.0f;  // offsetRayOrigin originScale of this scene
};

/** Camera rays in rtcIntersect16 packets of 4 x 4 pixels (default) or one rtcIntersect1 per
 *  path; for benchmarks (docs/reference.md, "Throughput"). Not thread-safe with rendering. */
void setCameraPackets(bool enabled);

/** The layer light arriving at surface vertex k (>= 1) belongs to. */
inline Layer layerForVertex(int k) {
    return k <= 1   ? Layer::Direct
           : k == 2 ? Layer::Bounce1
           : k == 3 ? Layer::Bounce2
                    : Layer::Bounce3Plus;
}

}  // namespace gilab::ref
