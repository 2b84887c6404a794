#pragma once
/**
 * Parameters of `cvgi` (clustered voxel GI, Cosin Ayerbe & Patow 2022; notes 000) and their parsed
 * form. Defaults are the paper's (or its authors' code's, where the paper is silent); every choice
 * is listed in techniques/cvgi/README.md.
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
    // The ray pattern (techniques/cvgi/README.md "seed"): every face's ray set rotated about its
    // normal by cvgi::seedRotation(seed) turns; 0 = the unrotated rays, bit for bit.
    uint32_t seed = 0;
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
    bool gaussianVisibility = true;  // ours: no filtering across occupied voxels
    bool interpolation = true;       // §4.5 bilinear face interpolation
    // The light bounce's estimator (set-up: the weights are built with the visibility lists):
    // Paper = each listed lit cluster through the face-to-cluster form factor (§4.4, Fig. 5);
    // RayWeighted = ours: the Monte Carlo estimate over the same rays, E = (2 pi / rays) sum over
    // the hits of the hit cluster's mean radiance times the ray's cosine.
    enum class Gather { Paper, RayWeighted } gather = Gather::Paper;
};

std::vector<ParamSpec> cvgiParamSpecs();
/** Parses and cross-checks (throws gilab::Error naming the parameter). */
CvgiSettings cvgiSettingsFrom(const ParamSet& params);

}  // namespace gilab
