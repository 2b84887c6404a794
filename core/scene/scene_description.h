#pragma once
/**
 * A scene description file (docs/scenes.md) parsed and validated, before any geometry is
 * loaded. Parsing is cheap, so the loader validates the base and every variant up front.
 */
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/scene/procedural_cornell.h"
#include "core/scene/procedural_rooms.h"
#include "core/scene/scene.h"

namespace gilab {

class JsonNode;

/** "camera": each field present overrides the camera the geometry source provides. */
struct CameraOverride {
    std::optional<glm::vec3> position;
    std::optional<glm::vec3> target;
    std::optional<glm::vec3> up;
    std::optional<float> vfovRad;
    std::optional<float> nearZ;
    std::optional<float> farZ;
    bool placesCamera() const { return position && target; }
};

/** One entry of "material_overrides" (applies to every material with that name). */
struct MaterialOverride {
    std::string name;
    std::optional<glm::vec4> baseColor;  // rgb + alpha (alpha kept when given as RGB)
    bool baseColorHasAlpha = false;
    std::optional<float> roughness;
    std::optional<float> metallic;
    std::optional<glm::vec3> emissive;
};

/** "animation" as parsed: light tracks name their light; indices are resolved by
 *  resolveAnimation once the scene's lights are final. */
struct AnimationDescription {
    SceneAnimation animation;
    std::vector<std::string> trackPaths;  // "animation.tracks[i]" per track, for messages
};

struct SceneDescription {
    std::string context;  // "scenes/x.json" or `scenes/x.json (variant "spot")`, for messages
    std::optional<std::string> name;
    std::string gltfPath;  // resolved against the file's folder; empty when procedural
    std::optional<CornellBoxParams> cornellBox;  // "procedural": at most one generator is set
    std::optional<TwoRoomsParams> twoRooms;
    std::optional<CameraOverride> camera;
    std::optional<glm::ivec2> resolution;
    std::optional<float> exposureEv;
    std::optional<std::vector<Light>> lights;  // replaces the source's lights
    std::vector<Light> extraLights;            // appended
    std::vector<MaterialOverride> materialOverrides;
    bool removeEmissive = false;
    /** Uniform scale of every length (geometry, camera, light positions; docs/scenes.md). */
    double scale = 1.0;
    /** Added to every position after `scale` (geometry, camera, point/spot lights; docs/scenes.md).
     */
    glm::dvec3 translate{0.0};
    std::optional<AnimationDescription> animation;
};

/**
 * Parses one description object (variants already merged in, "variants" removed). `baseDir`
 * is the folder relative paths are resolved against. Throws gilab::Error naming the key.
 */
SceneDescription parseSceneDescription(const JsonNode& root, const std::string& baseDir);

/** Parses one light object of "lights" / "extra_lights". */
Light parseLight(const JsonNode& node);

/** Parses an "animation" block (docs/scenes.md "Animation"); light indices stay unresolved. */
AnimationDescription parseAnimation(const JsonNode& node);

/**
 * The description's animation resolved against the built scene: light names become indices
 * into `scene.lights` (an unknown name lists the scene's lights), each light track must suit its
 * light's type, and the camera of every frame must stay valid. Empty without an animation.
 */
SceneAnimation resolveAnimation(const SceneDescription& d, const Scene& scene);

}  // namespace gilab
