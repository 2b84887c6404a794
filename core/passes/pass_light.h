#pragma once
/**
 * The pass light table: every light the rasteriser shades with, each with its shadow map.
 * Entries 0..n-1 are the scene's punctual lights in Scene::lights order (so GpuLight.cone.z =
 * the light's own index), then the emitter samples that stand in for emissive triangles.
 * Mirrored exactly by `PassLight` in shaders/common/lights.glsl; bound by ShadowMaps.
 */
#include <cstdint>

#include <glm/glm.hpp>

namespace gilab {

enum PassLightType : uint32_t {
    kPassLightPoint = 0,
    kPassLightSpot = 1,
    kPassLightDirectional = 2,
    kPassLightEmitterSample = 3,
};

enum ShadowKind : uint32_t {
    kShadowNone = 0,
    kShadowMap2D = 1,     // layer of the 2D array (spot, directional)
    kShadowCube = 2,      // cube of the point cube array (point lights, spots with outer > 85 deg)
    kShadowAreaCube = 3,  // cube of the emitter-sample cube array
};

struct PassLight {
    glm::vec4 positionType{0.0f};  // xyz position (not directional), w = PassLightType
    glm::vec4 direction{0.0f};     // xyz travel direction (spot, directional) or emitter normal;
                                   // w 1 = two-sided emitter sample
    glm::vec4 intensity{0.0f};     // rgb W/sr (point, spot), W/m^2 (directional), Le*A (sample);
                                   // w: sample area / pi (disk radius squared)
    glm::vec4 cone{0.0f};          // x cos(inner), y cos(outer) (spot)
    glm::vec4 shadow{0.0f};        // x ShadowKind, y layer / cube index, z texel size factor,
                                   // w 1 = orthographic (texel = z) else perspective (z * dist)
    glm::vec4 bias{0.0f};          // volume receivers (voxel centres): x constant, y slope,
                                   // z normal offset (texels), w PCF radius
    glm::vec4 surfaceBias{0.0f};   // surface receivers (the direct pass): the same four
    glm::vec4 cascades{0.0f};      // x first cascade entry, y count (directional lights),
                                   // z 1 = receiver-plane test for surface receivers,
                                   // w the cascade blend band (ShadowSettings::cascadeBlend)
    glm::vec4 origin{0.0f};        // orthographic: a point on the entry plane
    glm::mat4 viewProj{1.0f};      // 2D maps: world -> Vulkan clip space
};
static_assert(sizeof(PassLight) == 208);

}  // namespace gilab
