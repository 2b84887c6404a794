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
    return PrimaryRays(*this, width, height)(px, py);
}

PrimaryRays::PrimaryRays(const Camera& camera, int width, int height)
    : m_position(camera.position),
      m_forward(camera.forward()),
      m_right(camera.right()),
      m_up(camera.trueUp()),
      m_width(float(width)),
      m_height(float(height)),
      m_aspect(float(width) / float(height)),
      m_tanHalf(std::tan(0.5f * camera.vfovRad)) {}

}  // namespace gilab
