#pragma once
/**
 * The photons of `vct`'s light injection (notes 001 §2.5), shared by the dense splat and the sparse
 * voxel octree. One photon per light-map texel; invalid texels have positionValid.w = 0.
 * Mirrors Photon in shaders/vct/photon.glsl.
 */
#include <cstdint>

#include <glm/glm.hpp>

namespace gilab {
namespace vk {
class Buffer;
}

namespace vct {

struct GpuPhoton {
    glm::vec4 positionValid;  // xyz world position, w = 1 valid / 0 none
    glm::vec4 flux;           // rgb radiant flux (W) arriving at the surface
    glm::vec4 toLight;        // xyz unit direction toward the light
};
static_assert(sizeof(GpuPhoton) == 48);

/** A storage buffer of `count` GpuPhoton, written by the injection pass. */
struct PhotonSource {
    const vk::Buffer* buffer = nullptr;
    uint32_t count = 0;
};

}  // namespace vct
}  // namespace gilab
