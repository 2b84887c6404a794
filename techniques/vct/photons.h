#pragma once
/**
 * The photons of `vct`'s light injection (notes 001 §2.5), shared by the dense splat and the sparse
 * voxel octree. One photon per light-map texel; invalid texels have positionValid.w = 0.
 * Mirrors Photon in techniques/vct/shaders/photon.glsl.
 *
 * `flux` is what the light sends through the texel (so the buffer sums to the light's flux);
 * `irradiance` is the irradiance E = I(w) cos(theta) / r^2 (directional: E_perp cos(theta)) the
 * light produces on the surface at the hit, with the surface's shading normal `normal`. A valid
 * photon whose surface faces away from the light (normal . toLight <= 0) carries nothing: flux and
 * irradiance are 0. `irradiance.w` is the photon's light index (one per punctual light or emitter
 * sample; every view of a light shares it), so a splat can average E per light and voxel.
 */
#include <cstdint>

#include <glm/glm.hpp>

namespace gilab {
namespace vk {
class Buffer;
}

namespace vct {

struct GpuPhoton {
    glm::vec4 positionValid{0.0f};  // xyz world position, w = 1 valid / 0 none
    glm::vec4 flux{0.0f};           // rgb radiant flux (W) through the texel, w unused
    glm::vec4 toLight{0.0f};        // xyz unit direction toward the light, w unused
    glm::vec4 irradiance{0.0f};     // rgb irradiance (W/m^2) at the hit, w = light index (float)
    glm::vec4 normal{0.0f};         // xyz unit shading normal on the light's side, w = 1 when
                                    // the surface faces the light (else flux = E = 0)
};
static_assert(sizeof(GpuPhoton) == 80);

/** A storage buffer of `count` GpuPhoton, written by the injection pass. */
struct PhotonSource {
    const vk::Buffer* buffer = nullptr;
    uint32_t count = 0;
};

}  // namespace vct
}  // namespace gilab
