#pragma once
/**
 * Parameters of `ddgi` (Majercik et al. 2019, 2021; notes 005) and their parsed form. The spec
 * table drives help, validation and sweeps; DdgiSettings is what the passes read. Every value's
 * source (paper, the authors' G3D code, NVIDIA's RTXGI SDK) is listed in
 * techniques/ddgi/README.md beside our default.
 */
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/params/params.h"

namespace gilab {

enum class DdgiBias { SelfShadow, NormalView };  // paper 2 / G3D single bias | SDK b_n n + b_v w_o
enum class DdgiWarmStart { Ramp, Paper };        // running mean until alpha | alpha = 0 once

struct DdgiSettings {
    // Set-up (Rebuild): the volume, the atlases and the ray buffer.
    int probeGrid = 8;                // probes along the volume's longest axis
    glm::ivec3 probeCounts{0, 0, 0};  // explicit counts (0 = from probeGrid)
    float volumeScale = 0.9f;         // volume = scene bounds x this (G3D inscribed 0.9)
    int raysPerProbe = 256;
    int irradianceTexels = 6;  // interior octahedral texels per side (+ 1-texel border)
    int distanceTexels = 14;
    bool relocation = true;
    bool classification = false;
    // Per frame.
    float hysteresis = 0.97f;
    float irradianceGamma = 5.0f;
    float distanceExponent = 50.0f;
    float maxDistanceFactor = 1.5f;  // r_max = this x the cell diagonal
    DdgiBias biasMode = DdgiBias::SelfShadow;
    float selfShadowBias = 0.3f;  // x 0.75 x min spacing
    float normalBias = 0.1f;      // world units (normal_view)
    float viewBias = 0.1f;
    float chebyshevFloor = 0.05f;
    bool feedback = true;  // bounces = -1: E_prev at the probe-ray hits
    bool emissionInProbes = false;
    int hitLightSamples = 4;
    float hitTextureLod = 0.0f;
    float energyPreservation = 1.0f;
    float irradianceThreshold = 0.0f;
    float brightnessThreshold = 0.0f;
    float backfaceThreshold = 0.25f;       // fixed rays: inside geometry
    float randomBackfaceThreshold = 0.1f;  // per texel: leave unchanged
    float minFrontfaceDistance = 0.2f;     // x min spacing (relocation)
    int eventFrames = 0;
    DdgiWarmStart warmStart = DdgiWarmStart::Ramp;
    float settleTolerance = 0.005f;
    uint32_t seed = 1;

    /** Rays per probe that feed relocation and classification only (SDK: 32), else 0. */
    int fixedRays() const { return (relocation || classification) ? 32 : 0; }
};

std::vector<ParamSpec> ddgiParamSpecs();
/** Reads a validated ParamSet (ranges are checked by ParamSet; cross-key checks here). */
DdgiSettings ddgiSettingsFrom(const ParamSet& params);

}  // namespace gilab
