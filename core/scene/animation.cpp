// Scene animation: frame times, keyframe evaluation, frame states and their differences.
#include "core/scene/animation.h"

#include <algorithm>
#include <cmath>

#include "core/scene/scene.h"
#include "core/util/error.h"

namespace gilab {

namespace {

/** Spherical interpolation of two unit vectors, in double precision; always returns a unit vector.
 */
glm::dvec3 slerpUnit(const glm::dvec3& a, const glm::dvec3& b, double u) {
    const double cosTheta = glm::dot(a, b);
    const double sinTheta = glm::length(glm::cross(a, b));
    if (sinTheta < 1e-9 && cosTheta > 0.0) {
        // (Nearly) parallel: the arc is a line; normalised lerp
        const glm::dvec3 v = glm::mix(a, b, u);
        return v / glm::length(v);
    }
    if (sinTheta < 1e-9) {
        // Opposite: every great circle through a and -a is as short; take a fixed one, about
        // the axis least aligned with a
        const glm::dvec3 absA = glm::abs(a);
        const glm::dvec3 axis = absA.x <= absA.y && absA.x <= absA.z ? glm::dvec3(1, 0, 0)
                                : absA.y <= absA.z                   ? glm::dvec3(0, 1, 0)
                                                                     : glm::dvec3(0, 0, 1);
        const glm::dvec3 perp = glm::normalize(glm::cross(a, axis));
        const double angle = u * M_PI;
        const glm::dvec3 v = std::cos(angle) * a + std::sin(angle) * perp;
        return v / glm::length(v);
    }
    const double theta = std::atan2(sinTheta, cosTheta);
    const glm::dvec3 v =
        (std::sin((1.0 - u) * theta) * a + std::sin(u * theta) * b) / std::sin(theta);
    return v / glm::length(v);
}

glm::vec3 interpolate(const AnimationKey& k0, const AnimationKey& k1, double u,
                      Interpolation mode) {
    const glm::dvec3 a(k0.value), b(k1.value);
    if (mode == Interpolation::Slerp) {
        const double la = glm::length(a), lb = glm::length(b);
        if (la > 0.0 && lb > 0.0) return glm::vec3(slerpUnit(a / la, b / lb, u));
        return glm::vec3(glm::mix(a, b, u));  // not directions: plain lerp (never at load)
    }
    return glm::vec3(glm::mix(a, b, u));
}

/** The track's value at `time`: the end values hold outside the keys. */
glm::vec3 sampleTrack(const AnimationTrack& track, double time) {
    const std::vector<AnimationKey>& keys = track.keys;
    if (keys.empty()) throw Error("animation track without keys");
    if (!(time > keys.front().time)) return keys.front().value;
    if (!(time < keys.back().time)) return keys.back().value;
    const auto next = std::upper_bound(keys.begin(), keys.end(), time,
                                       [](double t, const AnimationKey& k) { return t < k.time; });
    const AnimationKey& k1 = *next;
    const AnimationKey& k0 = *(next - 1);
    const double u = (time - k0.time) / (k1.time - k0.time);
    return interpolate(k0, k1, std::clamp(u, 0.0, 1.0), track.interpolation);
}

bool isLightProperty(AnimationProperty p) {
    return p == AnimationProperty::LightPosition || p == AnimationProperty::LightDirection ||
           p == AnimationProperty::LightIntensity || p == AnimationProperty::LightColor;
}

bool sameLight(const Light& a, const Light& b) {
    return a.name == b.name && a.type == b.type && a.position == b.position &&
           a.direction == b.direction && a.intensity == b.intensity && a.color == b.color &&
           a.strength == b.strength && a.innerConeRad == b.innerConeRad &&
           a.outerConeRad == b.outerConeRad && a.range == b.range;
}

bool sameCamera(const Camera& a, const Camera& b) {
    return a.position == b.position && a.target == b.target && a.up == b.up &&
           a.vfovRad == b.vfovRad && a.nearZ == b.nearZ && a.farZ == b.farZ;
}

}  // namespace

const char* animationPropertyName(AnimationProperty property) {
    switch (property) {
        case AnimationProperty::LightPosition:
            return "position";
        case AnimationProperty::LightDirection:
            return "direction";
        case AnimationProperty::LightIntensity:
            return "intensity";
        case AnimationProperty::LightColor:
            return "color";
        case AnimationProperty::CameraPosition:
            return "position";
        case AnimationProperty::CameraTarget:
            return "target";
        case AnimationProperty::CameraFov:
            return "vfov_deg";
    }
    return "?";
}

std::string animationTarget(const AnimationTrack& track) {
    const std::string property = animationPropertyName(track.property);
    if (isLightProperty(track.property)) return "light:" + track.lightName + "." + property;
    return "camera." + property;
}

bool animationPropertyIsScalar(AnimationProperty property) {
    return property == AnimationProperty::LightIntensity ||
           property == AnimationProperty::CameraFov;
}

double SceneAnimation::frameTime(int frame) const {
    if (frameCount <= 1) return 0.0;
    const int f = std::clamp(frame, 0, frameCount - 1);
    if (f == frameCount - 1) return duration;  // exactly, whatever the rounding
    return duration * double(f) / double(frameCount - 1);
}

SceneFrameState evaluateAnimation(const Scene& scene, double time) {
    SceneFrameState state;
    state.lights = scene.lights;
    state.camera = scene.camera;
    for (const AnimationTrack& track : scene.animation.tracks) {
        const glm::vec3 v = sampleTrack(track, time);
        Light* light = nullptr;
        if (isLightProperty(track.property)) {
            if (track.lightIndex >= state.lights.size()) {
                throw Error("animation track " + animationTarget(track) + ": light index " +
                            std::to_string(track.lightIndex) + " out of range (" +
                            std::to_string(state.lights.size()) + " lights)");
            }
            light = &state.lights[track.lightIndex];
        }
        switch (track.property) {
            case AnimationProperty::LightPosition:
                light->position = v;
                break;
            case AnimationProperty::LightDirection: {
                glm::vec3 d = v;
                if (!(glm::length(d) > 1e-6f)) {
                    // A linear track between opposite keys passes through zero: take the arc
                    AnimationTrack arc = track;
                    arc.interpolation = Interpolation::Slerp;
                    d = sampleTrack(arc, time);
                }
                light->direction = glm::normalize(d);
                break;
            }
            case AnimationProperty::LightIntensity:
                light->strength = v.x;
                break;
            case AnimationProperty::LightColor:
                light->color = v;
                break;
            case AnimationProperty::CameraPosition:
                state.camera.position = v;
                break;
            case AnimationProperty::CameraTarget:
                state.camera.target = v;
                break;
            case AnimationProperty::CameraFov:
                state.camera.vfovRad = glm::radians(v.x);
                break;
        }
        if (track.property == AnimationProperty::LightIntensity ||
            track.property == AnimationProperty::LightColor) {
            light->intensity = light->color * light->strength;
        }
    }
    return state;
}

SceneFrameState frameState(const Scene& scene, int frame) {
    return evaluateAnimation(scene, scene.animation.frameTime(frame));
}

SceneChanges diffFrameStates(const SceneFrameState& from, const SceneFrameState& to) {
    SceneChanges changes;
    const size_t n = std::max(from.lights.size(), to.lights.size());
    for (size_t i = 0; i < n; ++i) {
        const bool both = i < from.lights.size() && i < to.lights.size();
        if (!both || !sameLight(from.lights[i], to.lights[i]))
            changes.lights.push_back(uint32_t(i));
    }
    changes.camera = !sameCamera(from.camera, to.camera);
    return changes;
}

void applyFrameState(Scene& scene, const SceneFrameState& state) {
    if (state.lights.size() != scene.lights.size()) {
        throw Error("applyFrameState: the state has " + std::to_string(state.lights.size()) +
                    " lights, the scene " + std::to_string(scene.lights.size()));
    }
    scene.lights = state.lights;
    scene.camera = state.camera;
}

}  // namespace gilab
