#pragma once
/**
 * The reference path tracer's settings types, apart from the tracer (reference/path_tracer.h)
 * so that code that only configures, names or keys a render (the cache key, experiment configs,
 * the command line) does not pull in Embree's side: the layers, the estimator, the pixel
 * filter, ReferenceSettings and its one JSON serialisation (settingsJson), the renderer
 * version, the stop criteria and the recorded-ray record.
 */
#include <cstdint>

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include "reference/sampling.h"

namespace gilab::ref {

enum class Layer : int { Full = 0, Emission, Direct, Bounce1, Bounce2, Bounce3Plus };
inline constexpr int kLayerCount = 6;
/** "full", "emission", "direct", "bounce1", "bounce2", "bounce3plus". */
const char* layerName(Layer layer);

/** Which estimator lights a path vertex: both combined by MIS (default), or one alone. */
enum class Estimator { Mis, NeeOnly, BsdfOnly };
const char* estimatorName(Estimator e);  // "mis", "nee", "bsdf"

/**
 * Where a pixel's camera rays go. Center (the default of the CLI and of experiment configs):
 * the rasteriser's footprint: every ray through the pixel centre (within 2^-10 px, so a centre
 * on an edge sees both faces), and the camera hit's textures filtered at the rasteriser's mip
 * level, so comparisons with techniques carry no antialiasing or texture-filtering differences.
 * Box: uniformly over the pixel's square, the antialiased image, textures at mip 0.
 */
enum class PixelFilter { Box, Center };
const char* pixelFilterName(PixelFilter f);  // "box", "center"

/** Bumped whenever a change alters the images; part of every reference cache key.
 *  3: roulette by default, wavefront (issue 16); 4: hit points step back along the arriving ray
 *  (concave edges), the centre filter is 2^-10 px wide and looks the camera hit's textures up
 *  at the rasteriser's mip level (issue 27); 5: ray origins off every nearby plane by error
 *  margins instead of steps that grow with |p| (reference/spawn.h), hit points from a double-
 *  precision plane intersection, emitters picked by their triangles' own mean radiance. */
inline constexpr int kRendererVersion = 5;

struct ReferenceSettings {
    /** Indirect bounces computed: 0 = emission + direct only; paths have at most
     *  maxBounces + 1 surface vertices. */
    int maxBounces = 32;
    /** Russian roulette on the continuation from vertices k > this (unbiased); -1 = off.
     *  Defaults since 2026-12-05 (issue 49): 2 and 0.2, 1.1-1.4x the efficiency of the old 4 and
     *  0.05 on three scenes (docs/reference.md, "Russian roulette"). */
    int rouletteStartBounce = 2;
    /** Roulette survival probability: min(1, max component of the throughput / this). */
    float rouletteThreshold = 0.2f;
    Estimator estimator = Estimator::Mis;
    uint64_t seed = 1;
    PixelFilter pixelFilter = PixelFilter::Center;
    /** Owen-scrambled Sobol in replicates (default since 2026-12-05, issue 49: 1.38-1.46x the
     *  efficiency on textured scenes, 1.00-1.03x on the Cornell box) or independent uniforms
     *  (exact per-pixel error bars at any count) (docs/reference.md, "Samplers"). */
    SamplerKind sampler = SamplerKind::Sobol;
    /** Sobol only: samples per independently scrambled replicate (a power of two); the spread of
     *  the replicates gives the per-pixel error bars (docs/reference.md, "Samplers"). */
    uint32_t sobolReplicate = 64;
    /** Samples added per pass over the image; the stop criteria are checked between passes. Up
     *  to 16 samples of a tile's pixels are traced as one wavefront (docs/reference.md). */
    uint32_t batchSamples = 16;
};

/**
 * Every field of `settings`, by name (snake_case; enums by their names): the one serialisation
 * of ReferenceSettings. It is the sidecar's "settings" block (reference/cache.cpp) and the cache
 * key hashes its dump (keySettingsJson, reference/scene_hash.h), so a field missing here would
 * let renders that differ in it share a cache entry. A new field goes here (a compile error in
 * reference_settings.cpp says so); if it does not change the image, name it in
 * kSettingsNotInKey (reference/scene_hash.h) as well.
 */
nlohmann::ordered_json settingsJson(const ReferenceSettings& settings);

/** When to stop: whichever comes first; 0 disables a criterion (at least one must be set). */
struct StopCriteria {
    uint64_t maxSamples = 0;
    double targetRelError = 0.0;  // meanRelativeStdError of the full layer
    double maxSeconds = 0.0;
};

/** A ray as traced, for benchmarks that replay the same rays against raw Embree. */
struct RecordedRay {
    glm::vec3 origin;
    glm::vec3 direction;
    float tNear;
    float tFar;
    bool shadow;  // occlusion query
};

}  // namespace gilab::ref
