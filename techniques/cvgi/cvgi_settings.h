#pragma once
/**
 * Parameters of `cvgi` (clustered voxel GI, Cosin Ayerbe & Patow 2022; notes 000) and their parsed
 * form. Defaults are the paper's (or its authors' code's, where the paper is silent); every choice
 * is listed in docs/techniques/cvgi.md.
 */
#include <cstdint>
#include <vector>

#include "core/params/params.h"

namespace gilab {

struct CvgiSettings {
    // Set-up (Rebuild): voxelization, clustering (Algorithm 1), per-face visibility (§4.3).
    uint32_t voxelResolution = 128;
    uint32_t initialClusters = 0;  // 0 = the paper's Table 4 value for the resolution
    uint32_t clusterIterations = 10;
    float clusterAngleDeg = 35.0f;
    uint32_t raysPerFace = 128;
    uint32_t shadowMapSize = 8192;  // emitter distance map (authors' code)
    uint32_t cameraMapSize = 256;   // "small" camera distance map (size not given)
    // Emitter update (§4.4): re-run when they change, no new set-up.
    float litBiasVoxels = 0.5f;
    float cameraBiasVoxels = 1.0f;
    bool neighbourTest = true;  // Fig. 10
    float nearClusterVoxels = 2.0f;
    uint32_t gaussianKernel = 5;  // 0 or 1 = off, else odd
    uint32_t gaussianPasses = 2;
    float gaussianSigmaVoxels = 1.0f;
    bool interpolation = true;  // §4.5 bilinear face interpolation
};

std::vector<ParamSpec> cvgiParamSpecs();
/** Parses and cross-checks (throws gilab::Error naming the parameter). */
CvgiSettings cvgiSettingsFrom(const ParamSet& params);

}  // namespace gilab
