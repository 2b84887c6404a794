#pragma once
/**
 * Pinhole camera: the single definition of view, projection and primary rays, used by the
 * rasteriser (view()/projection()) and the path tracer (primaryRay()). Pixel (x, y) has its
 * centre at (x + 0.5, y + 0.5); y = 0 is the top row of every image; aspect = width / height.
 */
#include <glm/glm.hpp>

namespace gilab {

struct Ray {
    glm::vec3 origin;
    glm::vec3 direction;  // unit length
};

struct Camera {
    glm::vec3 position{0.0f, 1.0f, 3.9f};
    glm::vec3 target{0.0f, 1.0f, 0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float vfovRad = 0.6858f;  // 39.3 degrees
    float nearZ = 0.01f;
    float farZ = 1000.0f;

    glm::vec3 forward() const;
    glm::vec3 right() const;
    glm::vec3 trueUp() const;
    /** World -> view (right-handed, camera looks down -z). */
    glm::mat4 view() const;
    /** View -> Vulkan clip space: depth in [0, 1], NDC y pointing down the image. */
    glm::mat4 projection(float aspect) const;
    /** Ray through image point (px, py) in pixel units, e.g. (x + 0.5, y + 0.5) for a centre. */
    Ray primaryRay(float px, float py, int width, int height) const;
};

}  // namespace gilab
