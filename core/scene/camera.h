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

/** Camera::primaryRay with the camera basis computed once (path tracers call it per sample);
 *  the same arithmetic, so the same rays bit for bit. */
class PrimaryRays {
public:
    PrimaryRays(const Camera& camera, int width, int height);
    Ray operator()(float px, float py) const {
        const float ndcX = 2.0f * px / m_width - 1.0f;
        const float ndcY = 1.0f - 2.0f * py / m_height;
        const glm::vec3 d =
            m_forward + ndcX * m_tanHalf * m_aspect * m_right + ndcY * m_tanHalf * m_up;
        return {m_position, glm::normalize(d)};
    }

private:
    glm::vec3 m_position, m_forward, m_right, m_up;
    float m_width, m_height, m_aspect, m_tanHalf;
};

}  // namespace gilab
