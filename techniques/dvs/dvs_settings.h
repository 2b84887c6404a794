#pragma once
/**
 * Parameters of `dvs` (deferred voxel shading, Villegas; notes 003) and their parsed form.
 * The spec table (dvsParamSpecs) drives help, validation and sweeps; DvsSettings is what the
 * passes read. Every source value is listed in techniques/dvs/README.md next to our default.
 */
#include <cstdint>
#include <string>
#include <vector>

#include "core/params/params.h"

namespace gilab {

enum class DvsLambert { NormalWeighted, Cosine };                // notes 003 E1-E3 | max(N.Psi, 0)
enum class DvsVoxelShadows { ShadowMap, Raycast, RaycastSoft };  // notes 003 §2.4, E4
enum class DvsPixelShadows { Shared, Cone };                     // shared direct layer | E13 cone
enum class DvsCombine { Physical, Source };                      // e + d + i | (d + i) * AO

struct DvsSettings {
    // Set-up (Rebuild): voxelization and the per-voxel lighting L1, F, G1, F.
    uint32_t voxelResolution = 128;
    DvsLambert lambert = DvsLambert::NormalWeighted;
    DvsVoxelShadows voxelShadows = DvsVoxelShadows::ShadowMap;
    float softShadowKappa = 0.25f;  // E4 kappa, t in grid-side units
    int bounces = 1;                // 1 = direct voxel light only; 2 = + G1
    // Per frame: the G-buffer cone trace.
    uint32_t diffuseCones = 6;
    float diffuseApertureDeg = 60.0f;
    bool specular = true;
    float specularApertureDeg = 0.0f;  // 0 = from roughness (half-power angle)
    DvsPixelShadows pixelShadows = DvsPixelShadows::Shared;
    float shadowConeApertureDeg = 5.0f;
    DvsCombine combine = DvsCombine::Physical;
    bool aoView = true;
    float aoFalloff = 10.0f;    // E11 lambda in 1 / grid side
    float stepFactor = 0.5f;    // E10 beta
    float maxDistance = 0.95f;  // grid sides
    float lodOffset = 0.0f;     // added to the radius level (Crassin §5; -1 = node-size reading)
    float lift = 1.5f;          // sample lift above the surface plane, cells (voxel_cone.glsl)
    bool liftBlend = false;     // lift_rule = blend
    float originOffset = 2.0f;  // voxels along the normal (and first step along the cone)
    float opacityCutoff = 0.99f;
};

std::vector<ParamSpec> dvsParamSpecs();
/** Reads a validated ParamSet (ranges are checked by ParamSet; cross-key checks here). */
DvsSettings dvsSettingsFrom(const ParamSet& params);

/** Full specular cone aperture (deg) for a GGX perceptual roughness: Phong exponent
 *  n = 2 / alpha^2 - 2 (alpha = roughness^2), half angle = arccos(0.5^(1/n)) (half-power angle
 *  of the cos^n lobe), full angle clamped to [1, 60] deg. Mirrored in
 * techniques/dvs/shaders/trace.comp. */
float dvsSpecularApertureDeg(float roughness);

/** Full apex angle of the repo's G1 bounce cones: tan(theta/2) = 0.5 (notes 003 §2.6). */
inline constexpr uint32_t kDvsBounceConeCount = 4;
float dvsBounceApertureDeg();

/** The light-sample distance floor of L1 in voxels (emitter samples near a voxel,
 *  techniques/dvs/README.md). */
inline constexpr float kDvsEmitterMinDistanceVoxels = 1.0f;

}  // namespace gilab
