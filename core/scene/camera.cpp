#include "core/scene/camera.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace gilab {

glm::vec3 Camera::forward() const {
    return glm::normalize(target - position);
}
glm::vec3 Camera::right() const {
    return glm::normalize(glm::cross(forward(), up));
}
glm::vec3 Camera::trueUp() const {
    return glm::cross(right(), forward());
}

glm::mat4 Camera::view() const {
    return glm::lookAtRH(position, target, up);
}

glm::mat4 Camera::projection(float aspect) const {
    glm::mat4 p = glm::perspectiveRH_ZO(vfovRad, aspect, nearZ, farZ);
    p[1][1] *= -1.0f;  // Vulkan NDC y points down: row 0 of the image is the top
    return p;
}

Ray Camera::primaryRay(float px, float py, int width, int height) const {
    const float aspect = float(width) / float(height);
    const float tanHalf = std::tan(0.5f * vfovRad);
    const float ndcX = 2.0f * px / float(width) - 1.0f;
    const float ndcY = 1.0f - 2.0f * py / float(height);
    const glm::vec3 d = forward() + ndcX * tanHalf * aspect * right() + ndcY * tanHalf * trueUp();
    return {position, glm::normalize(d)};
}

}  // namespace gilab
