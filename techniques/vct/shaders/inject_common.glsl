// Shared declarations of vct's dense splat and shade passes (techniques/vct/light_injection.cpp).
// Set 0: binding 0 photons, 1 the voxelizer's albedoOpacity volume, 2 three flux planes of N^3
// words (r, g, b; float sums, or uint fixed point when INJECT_FIXED_POINT), 3 the radiance
// volume's base (shade only; INJECT_FORMAT = rgba16f or rgba32f), 4 three irradiance planes
// (sum over lights of each light's mean photon irradiance; float or fixed point), 5 the photon
// count (fixed point) or deposit area (float) of the light being splatted per voxel, 6 the light
// views.
#ifndef GILAB_VCT_INJECT_COMMON_GLSL
#define GILAB_VCT_INJECT_COMMON_GLSL

#include "common/voxel_grid.glsl"
#include "light_view.glsl"
#include "photon.glsl"

layout(set = 0, binding = 0, std430) readonly buffer Photons {
    Photon photons[];
};
layout(set = 0, binding = 1) uniform sampler3D voxelAlbedoOpacity;
#ifdef INJECT_FIXED_POINT
layout(set = 0, binding = 2, std430) buffer FluxPlanes {
    uint v[];
} fluxPlanes[3];
layout(set = 0, binding = 4, std430) buffer IrradiancePlanes {
    uint v[];
} irradiancePlanes[3];
#else
layout(set = 0, binding = 2, std430) buffer FluxPlanes {
    float v[];
} fluxPlanes[3];
layout(set = 0, binding = 4, std430) buffer IrradiancePlanes {
    float v[];
} irradiancePlanes[3];
#endif
#ifdef INJECT_FIXED_POINT
layout(set = 0, binding = 5, std430) buffer CountPlane {
    uint photonCount[];
};
#else
// Float accumulation: the summed footprint area of the deposits per voxel (m^2), so the voxel's
// irradiance is the area-weighted mean (splat_dense_body.glsl)
layout(set = 0, binding = 5, std430) buffer WeightPlane {
    float depositArea[];
};
#endif
layout(set = 0, binding = 6, std430) readonly buffer LightViews {
    LightView views[];
};

// Mirrored by InjectPush in techniques/vct/light_injection.cpp.
layout(push_constant, std430) uniform InjectPush {
    VoxelGridInfo grid;
    vec4 scale;    // x fixed-point flux units per W, y W per unit, z irradiance units per W/m^2,
                   // w W/m^2 per unit
    uvec4 counts;  // x photons in the range, y first photon, z mode (INJECT_MODE_*)
    uvec4 light;   // x first view of the light being splatted, y its view count
    vec4 params;   // x irradiance cap per photon (fixed point only)
} pc;

#define INJECT_MODE_COUNT 0u       // flux point splat + photon count per voxel
#define INJECT_MODE_IRRADIANCE 1u  // add E / count per voxel

#endif  // GILAB_VCT_INJECT_COMMON_GLSL
