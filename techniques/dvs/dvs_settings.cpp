#include "dvs_settings.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/voxel/voxel_grid.h"

namespace gilab {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr ParamStage kRebuild = ParamStage::Rebuild;

}  // namespace

std::vector<ParamSpec> dvsParamSpecs() {
    return {
        // Set-up: voxelization + per-voxel lighting (re-run by the source when lights change).
        requirePowerOfTwo(intParam("voxel_resolution", 128, VoxelGrid::kMinResolution,
                                   VoxelGrid::kMaxResolution, "voxels",
                                   "voxels per grid axis N (source repo default 256); a power of "
                                   "two (the directional mips halve it down to 1)",
                                   kRebuild)),
        enumParam("voxel_lambert", "normal_weighted", {"normal_weighted", "cosine"},
                  "per-voxel diffuse term: normal_weighted = the paper's per-axis weighting "
                  "(techniques/dvs/README.md) | cosine = plain max(N.Psi, 0)",
                  kRebuild),
        enumParam("voxel_shadows", "shadow_map", {"shadow_map", "raycast", "raycast_soft"},
                  "per-voxel occlusion: shared shadow maps | hard voxel ray | soft ray (E4)",
                  kRebuild),
        floatParam("soft_shadow_kappa", 0.25, 1e-4, 10.0, "",
                   "E4 kappa per occupied voxel (repo 0.5^2), t in grid-side units", kRebuild),
        intParam("bounces", 1, 1, 2, "",
                 "indirect bounces: 1 = direct voxel light, 2 = + per-voxel cone gather (G1)",
                 kRebuild),
        // Per frame: cone tracing from the G-buffer.
        intParam("diffuse_cones", 6, 1, 16, "", "diffuse cones per pixel (source 6)"),
        floatParam("diffuse_aperture_deg", 60.0, 5.0, 120.0, "deg",
                   "full aperture of each diffuse cone (source 60)"),
        boolParam("specular", true, "indirect specular cone on glossy pixels"),
        allowValue(0, floatParam("specular_aperture_deg", 0.0, 1.0, 60.0, "deg",
                                 "specular cone aperture; 0 = from roughness (half-power), source "
                                 "test 10 (narrower than 1 deg needs sub-voxel steps)")),
        enumParam("pixel_shadows", "shared", {"shared", "cone"},
                  "direct-light shadows: keep the shared layer | recompute with a shadow cone"),
        floatParam("shadow_cone_aperture_deg", 5.0, 0.5, 60.0, "deg",
                   "shadow cone aperture (source shows 1, 5, 10, 25)"),
        enumParam("combine", "physical", {"physical", "source"},
                  "physical: e + d + i | source: (d + i) * AO (not physically based)"),
        boolParam("ao_view", true, "compute the AO debug view (E11-E12)"),
        floatParam("ao_falloff", 10.0, 0.0, 2000.0, "1/grid side",
                   "E11 lambda: f(r) = 1 / (1 + lambda r / G) (repo 800)"),
        floatParam("step_factor", 0.5, 0.05, 4.0, "", "E10 beta: step = beta x cone diameter"),
        floatParam("max_distance", 0.95, 0.01, 2.0, "grid sides", "cone length limit (repo 0.95)"),
        floatParam("lod_offset", 0.0, -2.0, 2.0, "levels",
                   "added to the cone level log2(radius / v0) (0 = the radius level, one finer "
                   "than E7's diameter level, as the repo samples; techniques/dvs/README.md)"),
        floatParam("lift", 1.5, 0.0, 4.0, "cells",
                   "keep each sample >= lift x v0 x 2^ceil(L) above the surface plane (no "
                   "self-gather; 0 = off; docs/voxel_cone_tracing.md)"),
        enumParam("lift_rule", "cell", {"cell", "blend"},
                  "cell: clear the coarser blended level's cell 2^ceil(L) (exact); blend: the two "
                  "cell sizes mixed by the level weight (continuous in t)"),
        floatParam("origin_offset", 2.0, 0.0, 8.0, "voxels",
                   "cone origin offset along the normal, and first step (repo 2)"),
        floatParam("opacity_cutoff", 0.99, 0.5, 1.0, "", "stop a cone at this opacity"),
    };
}

DvsSettings dvsSettingsFrom(const ParamSet& p) {
    DvsSettings s;
    s.voxelResolution = uint32_t(p.getInt("voxel_resolution"));
    s.lambert =
        p.getEnum("voxel_lambert") == "cosine" ? DvsLambert::Cosine : DvsLambert::NormalWeighted;
    const std::string shadows = p.getEnum("voxel_shadows");
    s.voxelShadows = shadows == "raycast"        ? DvsVoxelShadows::Raycast
                     : shadows == "raycast_soft" ? DvsVoxelShadows::RaycastSoft
                                                 : DvsVoxelShadows::ShadowMap;
    s.softShadowKappa = p.getFloat("soft_shadow_kappa");
    s.bounces = p.getInt("bounces");
    s.diffuseCones = uint32_t(p.getInt("diffuse_cones"));
    s.diffuseApertureDeg = p.getFloat("diffuse_aperture_deg");
    s.specular = p.getBool("specular");
    s.specularApertureDeg = p.getFloat("specular_aperture_deg");
    s.pixelShadows =
        p.getEnum("pixel_shadows") == "cone" ? DvsPixelShadows::Cone : DvsPixelShadows::Shared;
    s.shadowConeApertureDeg = p.getFloat("shadow_cone_aperture_deg");
    s.combine = p.getEnum("combine") == "source" ? DvsCombine::Source : DvsCombine::Physical;
    s.aoView = p.getBool("ao_view");
    s.aoFalloff = p.getFloat("ao_falloff");
    s.stepFactor = p.getFloat("step_factor");
    s.maxDistance = p.getFloat("max_distance");
    s.lodOffset = p.getFloat("lod_offset");
    s.lift = p.getFloat("lift");
    s.liftBlend = p.getEnum("lift_rule") == "blend";
    s.originOffset = p.getFloat("origin_offset");
    s.opacityCutoff = p.getFloat("opacity_cutoff");
    return s;
}

float dvsSpecularApertureDeg(float roughness) {
    const float r = std::clamp(roughness, 0.0f, 1.0f);
    const float alpha = std::max(r * r, 1.0e-3f);
    const float exponent = 2.0f / (alpha * alpha) - 2.0f;  // Phong exponent of the GGX lobe
    float halfRad = float(kPi / 2.0);
    if (exponent > 1.0e-4f) halfRad = std::acos(std::pow(0.5f, 1.0f / exponent));
    const float fullDeg = 2.0f * halfRad * float(180.0 / kPi);
    return std::clamp(fullDeg, 1.0f, 60.0f);
}

float dvsBounceApertureDeg() {
    return float(2.0 * std::atan(0.5) * 180.0 / kPi);
}

}  // namespace gilab
