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
 *
 * Paths are traced as a wavefront (docs/reference.md, "Wavefront"): all live paths' rays of one
 * depth go to Embree (camera rays in 16-wide packets, bounce rays in one rtcIntersect1M
 * stream), then every hit is shaded (queuing its shadow rays),
 * then all shadow rays are traced in one rtcOccluded1M stream and the unoccluded ones add their
 * light. Each path's arithmetic and random numbers are those of tracing it alone, in the same
 * order.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/camera.h"
#include "reference/embree_scene.h"
#include "reference/path_tracer.h"
#include "reference/sampling.h"
#include "reference/spawn.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {

class LightSampler;

/** Radiance of one camera path per layer (index = Layer); Full = the sum of the others. */
struct PathRadiance {
    glm::vec3 L[kLayerCount];
};

struct PathCounters {
    uint64_t cameraRays = 0;
    uint64_t bounceRays = 0;
    uint64_t shadowRays = 0;
};

/** One path in flight: its next ray, throughput and random-number stream. */
struct PathState {
    Sampler sampler;
    glm::vec3 rayO{0.0f};
    glm::vec3 rayD{0.0f, 0.0f, 1.0f};  // unit
    glm::vec3 beta{1.0f};
    float prevBsdfPdf = 0.0f;  // solid-angle pdf of the ray that leads to `vertex`
    int vertex = 1;            // the surface vertex the current ray hits
    uint32_t slot = 0;         // index of this path's PathRadiance
    RayHit hit;
    bool found = false;
    // The camera hit's texture footprint (pixel-centre rays): vertex 1 then looks its textures up
    // at the rasteriser's mip level, as the G-buffer does (docs/reference.md, "Pixel filter").
    bool hasFootprint = false;
    TextureFootprint footprint;
};

/** A shadow ray of one vertex and the light it adds to `slot`'s layer if unoccluded. */
struct ShadowRay {
    glm::vec3 o;
    glm::vec3 d;
    float tFar;
    glm::vec3 contribution;
    uint32_t slot;
    int layer;
};

/** Per-thread buffers of tracePaths (reused between calls). */
struct WaveScratch {
    std::vector<uint32_t> active, next;
    std::vector<ShadowRay> shadows;
    std::vector<RTCRay> shadowRays;     // the stream handed to rtcOccluded1M
    std::vector<RTCRayHit> bounceRays;  // the stream handed to rtcIntersect1M
};

class Integrator {
public:
    Integrator(const Scene& scene, const ReferenceSettings& settings, const EmbreeScene& mesh,
               const LightSampler& lights, const TextureLookup& textures);

    /**
     * Traces every path from its camera ray (rayO, rayD set, vertex = 1) to its end; out[slot]
     * receives the path's radiance per layer. `cameraHitsKnown`: the paths' hit/found already
     * hold the camera ray's closest hit (the centre filter traces them first, for the texture
     * footprint). `packets`:
     * rtcIntersect16 + an rtcOccluded1M stream (default) or one rtcIntersect1/rtcOccluded1
     * per ray (benchmarks; the same estimator). `sink` receives every ray traced, or nullptr.
     */
    void tracePaths(std::vector<PathState>& paths, PathRadiance* out, bool cameraHitsKnown,
                    bool packets, PathCounters& counters, std::vector<RecordedRay>* sink,
                    WaveScratch& scratch) const;

private:
    /** Shades path p's hit: emission, NEE (queued on `shadows`), BSDF sampling of the next
     *  ray. Returns whether the path goes on. */
    bool shade(PathState& p, PathRadiance& out, std::vector<ShadowRay>& shadows) const;

    void prefetchTriangle(const PathState& p) const;
    void prefetchTexels(const PathState& p) const;

    void traceClosest(std::vector<PathState>& paths, const std::vector<uint32_t>& active,
                      bool packets, bool coherent, std::vector<RTCRayHit>& stream) const;
    void traceShadows(const std::vector<ShadowRay>& shadows, std::vector<RTCRay>& stream,
                      PathRadiance* out, bool packets) const;

    const Scene& m_scene;
    const ReferenceSettings& m_settings;
    const EmbreeScene& m_mesh;
    const LightSampler& m_lights;
    const TextureLookup& m_textures;
    SpawnOffsets m_spawn;  // ray origins off every nearby surface
};

/** Closest-hit packets and a shadow-ray stream (default) or one Embree call per ray; for benchmarks
 *  (docs/reference.md, "Throughput"). Not thread-safe with rendering. */
void setRayPackets(bool enabled);

/** The layer light arriving at surface vertex k (>= 1) belongs to. */
inline Layer layerForVertex(int k) {
    return k <= 1   ? Layer::Direct
           : k == 2 ? Layer::Bounce1
           : k == 3 ? Layer::Bounce2
                    : Layer::Bounce3Plus;
}

}  // namespace gilab::ref
