#pragma once
/**
 * Triangle / axis-aligned box overlap by the separating axis theorem (Akenine-Moller 2001),
 * closed (touching counts). The CPU twin of shaders/common/voxel_sat.glsl, for tests and
 * CPU-side checks of the GPU voxelization.
 */
#include <glm/glm.hpp>

namespace gilab {

bool triangleBoxOverlap(const glm::vec3& center, const glm::vec3& halfSize, const glm::vec3& a,
                        const glm::vec3& b, const glm::vec3& c);

}  // namespace gilab
