#pragma once
/**
 * Scene animation (docs/scenes.md "Animation"): keyframed tracks that move lights and the
 * camera over a fixed number of frames. A scene without an "animation" block has an empty
 * SceneAnimation and is static.
 *
 *   frame f of N has time t_f = duration * f / (N - 1)   (t_0 = 0, t_{N-1} = duration; N = 1: 0)
 *   between keys: linear interpolation, or slerp for directions (unit vectors); before the
 *   first key / after the last one the end value holds.
 *
 * Rigid transforms of mesh nodes are not supported yet (SceneChanges::geometry stays false);
 * a track naming a node is rejected when the description is parsed.
 */
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/camera.h"

namespace gilab {

struct Light;
struct Scene;

enum class AnimationProperty : uint32_t {
    LightPosition,   // vec3, metres
    LightDirection,  // vec3, unit (the direction light travels); slerp by default
    LightIntensity,  // scalar: the description's "intensity" (Light::strength)
    LightColor,      // vec3: the description's "color" (Light::color)
    CameraPosition,  // vec3
    CameraTarget,    // vec3
    CameraFov,       // scalar: vertical field of view in degrees
};

enum class Interpolation : uint32_t { Linear, Slerp };

struct AnimationKey {
    double time = 0.0;      // seconds, strictly increasing within a track
    glm::vec3 value{0.0f};  // scalars in .x
};

struct AnimationTrack {
    AnimationProperty property = AnimationProperty::LightPosition;
    std::string lightName;    // light tracks: the light's "name"
    uint32_t lightIndex = 0;  // light tracks: index into Scene::lights (resolved at load)
    Interpolation interpolation = Interpolation::Linear;
    std::vector<AnimationKey> keys;  // at least one
};

struct SceneAnimation {
    double duration = 0.0;  // seconds
    int frameCount = 0;     // 0 = no animation
    std::vector<AnimationTrack> tracks;

    bool animated() const { return frameCount > 0 && !tracks.empty(); }
    /** t_f as above (`frame` is clamped to [0, N - 1]; the last frame is exactly `duration`). */
    double frameTime(int frame) const;
};

/** Lights and camera of one instant (everything an animation can change). */
struct SceneFrameState {
    std::vector<Light> lights;
    Camera camera;
};

/** What changed between two frame states. */
struct SceneChanges {
    std::vector<uint32_t> lights;  // indices into Scene::lights whose data changed
    bool camera = false;
    bool geometry = false;  // always false until node transforms exist
    bool any() const { return !lights.empty() || camera || geometry; }
};

/** The scene's lights and camera at time `t` (the static scene's values where no track). */
SceneFrameState evaluateAnimation(const Scene& scene, double time);
/** The state of frame `frame` of the scene's animation (frame 0 for a static scene). */
SceneFrameState frameState(const Scene& scene, int frame);
/** Exact comparison of every light field and the camera (no tolerance: same input, same key). */
SceneChanges diffFrameStates(const SceneFrameState& from, const SceneFrameState& to);
/** Writes a frame state into a scene (lights, camera); the geometry is untouched. The light
 *  counts must match (gilab::Error otherwise). */
void applyFrameState(Scene& scene, const SceneFrameState& state);

/** The property's name in a track target: "position", "direction", "intensity", "color",
 *  "target", "vfov_deg". */
const char* animationPropertyName(AnimationProperty property);
/** The track's target as written in a description: "light:<name>.<property>" or
 *  "camera.<property>". */
std::string animationTarget(const AnimationTrack& track);
/** Intensity and field of view are scalars (AnimationKey::value.x); the rest are vec3. */
bool animationPropertyIsScalar(AnimationProperty property);

}  // namespace gilab
