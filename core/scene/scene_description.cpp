#include "core/scene/scene_description.h"

#include <cmath>
#include <filesystem>

#include <glm/gtc/constants.hpp>

#include "core/util/error.h"
#include "core/util/json_reader.h"

namespace gilab {

namespace {

/** A unit direction: "direction" as given, or "target" - position. */
glm::vec3 readDirection(const JsonNode& node, const std::optional<glm::vec3>& position) {
    const bool hasDir = node.has("direction"), hasTarget = node.has("target");
    if (hasDir == hasTarget) node.fail("give exactly one of \"direction\" and \"target\"");
    if (hasTarget && !position) node.fail("\"target\" needs a \"position\"");
    const JsonNode key = hasDir ? node["direction"] : node["target"];
    const glm::vec3 d = hasDir ? key.vec3() : key.vec3() - *position;
    const float len = glm::length(d);
    if (!(len > 1e-6f)) key.fail(hasDir ? "zero-length direction" : "target equals position");
    return d / len;
}

CameraOverride parseCamera(const JsonNode& node) {
    node.expectKeys({"position", "target", "up", "vfov_deg", "near", "far"});
    CameraOverride cam;
    if (node.has("position")) cam.position = node["position"].vec3();
    if (node.has("target")) cam.target = node["target"].vec3();
    if (node.has("up")) {
        cam.up = node["up"].vec3();
        if (!(glm::length(*cam.up) > 1e-6f)) node["up"].fail("zero-length up vector");
    }
    if (node.has("vfov_deg")) {
        const double deg = node["vfov_deg"].numberIn(0.0, 179.0);
        if (!(deg > 0.0)) node["vfov_deg"].fail("must be > 0");
        cam.vfovRad = glm::radians(float(deg));
    }
    if (node.has("near")) cam.nearZ = float(node["near"].numberIn(1e-6, 1e9));
    if (node.has("far")) cam.farZ = float(node["far"].numberIn(1e-6, 1e9));
    if (cam.position && cam.target && glm::length(*cam.target - *cam.position) < 1e-6f) {
        node.fail("camera position equals target");
    }
    if (cam.nearZ && cam.farZ && !(*cam.farZ > *cam.nearZ)) node.fail("far must exceed near");
    return cam;
}

MaterialOverride parseMaterialOverride(const JsonNode& node, const std::string& name) {
    node.expectKeys({"base_color", "roughness", "metallic", "emissive"});
    MaterialOverride o;
    o.name = name;
    if (node.has("base_color")) {
        const JsonNode c = node["base_color"];
        const size_t n = c.arraySize();
        if (n != 3 && n != 4) c.fail("expected [r, g, b] or [r, g, b, a]");
        glm::vec4 v(1.0f);
        for (size_t i = 0; i < n; ++i)
            v[int(i)] = float(c.item(i).numberIn(0.0, 1.0));
        o.baseColor = v;
        o.baseColorHasAlpha = n == 4;
    }
    if (node.has("roughness")) o.roughness = float(node["roughness"].numberIn(0.0, 1.0));
    if (node.has("metallic")) o.metallic = float(node["metallic"].numberIn(0.0, 1.0));
    if (node.has("emissive")) o.emissive = node["emissive"].color();
    return o;
}

std::vector<Light> parseLights(const JsonNode& node) {
    std::vector<Light> lights;
    for (size_t i = 0; i < node.arraySize(); ++i)
        lights.push_back(parseLight(node.item(i)));
    return lights;
}

struct AnimationTarget {
    AnimationProperty property = AnimationProperty::LightPosition;
    std::string lightName;
};

AnimationTarget parseAnimationTarget(const JsonNode& node) {
    const std::string t = node.string();
    const char* kForms =
        "light:<name>.position|direction|intensity|color, camera.position|target|vfov_deg";
    AnimationTarget target;
    if (t.rfind("node:", 0) == 0) {
        node.fail("\"" + t + "\": rigid node transforms are not supported yet (animate lights " +
                  "and the camera: " + kForms + ")");
    }
    if (t.rfind("camera.", 0) == 0) {
        const std::string prop = t.substr(7);
        if (prop == "position")
            target.property = AnimationProperty::CameraPosition;
        else if (prop == "target")
            target.property = AnimationProperty::CameraTarget;
        else if (prop == "vfov_deg")
            target.property = AnimationProperty::CameraFov;
        else
            node.fail("unknown camera property \"" + prop + "\" (position, target, vfov_deg)");
        return target;
    }
    if (t.rfind("light:", 0) == 0) {
        const size_t dot = t.rfind('.');
        if (dot == std::string::npos || dot <= 6) {
            node.fail("\"" + t + "\": expected \"light:<name>.<property>\"");
        }
        target.lightName = t.substr(6, dot - 6);
        const std::string prop = t.substr(dot + 1);
        if (prop == "position")
            target.property = AnimationProperty::LightPosition;
        else if (prop == "direction")
            target.property = AnimationProperty::LightDirection;
        else if (prop == "intensity")
            target.property = AnimationProperty::LightIntensity;
        else if (prop == "color")
            target.property = AnimationProperty::LightColor;
        else
            node.fail("unknown light property \"" + prop +
                      "\" (position, direction, intensity, color)");
        return target;
    }
    node.fail("unknown target \"" + t + "\" (expected " + kForms + ")");
}

/** One key's value, checked for the property (float-finite, ranges; directions normalised). */
glm::vec3 parseKeyValue(const JsonNode& node, AnimationProperty property) {
    if (animationPropertyIsScalar(property)) {
        double v = 0.0;
        if (property == AnimationProperty::LightIntensity) {
            v = node.numberIn(0.0, 1e12);
        } else {
            v = node.number();
            if (!(v > 0.0 && v < 180.0)) {
                node.fail("out of range: a field of view must be in (0, 180) degrees (got " +
                          node.raw().dump() + ")");
            }
        }
        return glm::vec3(float(v), 0.0f, 0.0f);
    }
    glm::vec3 v = property == AnimationProperty::LightColor ? node.color(1e12) : node.vec3();
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
        node.fail("value out of the float range");
    }
    if (property == AnimationProperty::LightDirection) {
        const float len = glm::length(v);
        if (!(len > 1e-6f) || !std::isfinite(len)) node.fail("zero-length direction");
        v /= len;
    }
    return v;
}

}  // namespace

AnimationDescription parseAnimation(const JsonNode& node) {
    node.expectKeys({"duration_s", "frames", "tracks"});
    AnimationDescription out;
    SceneAnimation& a = out.animation;
    a.frameCount = node["frames"].integerIn(1, 10000);
    a.duration = node["duration_s"].numberIn(0.0, 1e9);
    if (!(a.duration > 0.0) && a.frameCount != 1) {
        node["duration_s"].fail("must be > 0 (0 only with \"frames\": 1)");
    }
    const JsonNode tracks = node["tracks"];
    if (tracks.arraySize() == 0) tracks.fail("expected at least one track");
    for (size_t i = 0; i < tracks.arraySize(); ++i) {
        const JsonNode t = tracks.item(i);
        t.expectKeys({"target", "interpolation", "keys"});
        AnimationTrack track;
        const AnimationTarget target = parseAnimationTarget(t["target"]);
        track.property = target.property;
        track.lightName = target.lightName;
        const bool direction = track.property == AnimationProperty::LightDirection;
        track.interpolation = direction ? Interpolation::Slerp : Interpolation::Linear;
        if (t.has("interpolation")) {
            const JsonNode mode = t["interpolation"];
            const std::string name = mode.string();
            if (name == "linear") {
                track.interpolation = Interpolation::Linear;
            } else if (name == "slerp") {
                if (!direction) mode.fail("slerp applies to direction tracks only (use linear)");
                track.interpolation = Interpolation::Slerp;
            } else {
                mode.fail("unknown interpolation \"" + name + "\" (linear, slerp)");
            }
        }
        const JsonNode keys = t["keys"];
        if (keys.arraySize() == 0) keys.fail("expected at least one key [time, value]");
        for (size_t k = 0; k < keys.arraySize(); ++k) {
            const JsonNode key = keys.item(k);
            if (key.arraySize() != 2) key.fail("expected [time, value]");
            AnimationKey parsed;
            parsed.time = key.item(0).number();
            if (k > 0 && !(parsed.time > track.keys.back().time)) {
                key.item(0).fail("key times must increase strictly (got " +
                                 key.item(0).raw().dump() + " after " +
                                 keys.item(k - 1).item(0).raw().dump() + ")");
            }
            parsed.value = parseKeyValue(key.item(1), track.property);
            track.keys.push_back(parsed);
        }
        const std::string name = animationTarget(track);
        for (size_t j = 0; j < a.tracks.size(); ++j) {
            if (animationTarget(a.tracks[j]) == name) {
                t["target"].fail("a second track for \"" + name + "\" (" + out.trackPaths[j] +
                                 " animates it already)");
            }
        }
        a.tracks.push_back(std::move(track));
        out.trackPaths.push_back(t.path());
    }
    return out;
}

SceneAnimation resolveAnimation(const SceneDescription& d, const Scene& scene) {
    if (!d.animation) return SceneAnimation{};
    SceneAnimation a = d.animation->animation;
    bool cameraTracks = false;
    for (size_t i = 0; i < a.tracks.size(); ++i) {
        AnimationTrack& track = a.tracks[i];
        const std::string where = d.context + ": \"" + d.animation->trackPaths[i] + ".target\": ";
        const AnimationProperty p = track.property;
        if (p == AnimationProperty::CameraPosition || p == AnimationProperty::CameraTarget ||
            p == AnimationProperty::CameraFov) {
            cameraTracks = true;
            continue;
        }
        std::vector<uint32_t> matches;
        std::string names;
        for (size_t l = 0; l < scene.lights.size(); ++l) {
            if (scene.lights[l].name == track.lightName) matches.push_back(uint32_t(l));
            names += (names.empty() ? "" : ", ") + scene.lights[l].name;
        }
        if (matches.empty()) {
            throw Error(where + "unknown light \"" + track.lightName + "\" (" +
                        (names.empty() ? "the scene has no lights" : "the scene has: " + names) +
                        ")");
        }
        if (matches.size() > 1) {
            throw Error(where + std::to_string(matches.size()) + " lights are named \"" +
                        track.lightName + "\"; give them distinct names");
        }
        const Light& light = scene.lights[matches[0]];
        if (p == AnimationProperty::LightDirection && light.type == LightType::Point) {
            throw Error(where + "light \"" + light.name +
                        "\" is a point light: it has no direction");
        }
        if (p == AnimationProperty::LightPosition && light.type == LightType::Directional) {
            throw Error(where + "light \"" + light.name +
                        "\" is a directional light: its position is not used");
        }
        track.lightIndex = matches[0];
    }
    if (cameraTracks) {
        // Every frame's camera must be usable (a moving position may meet a moving target).
        Scene probe;
        probe.lights = scene.lights;
        probe.camera = scene.camera;
        probe.animation = a;
        for (int f = 0; f < a.frameCount; ++f) {
            const Camera c = frameState(probe, f).camera;
            const std::string where = d.context + ": \"animation\": frame " + std::to_string(f) +
                                      " (t = " + std::to_string(a.frameTime(f)) + " s): ";
            const glm::vec3 forward = c.target - c.position;
            if (!(glm::length(forward) > 1e-6f))
                throw Error(where + "camera position equals target");
            if (!(glm::length(glm::cross(glm::normalize(forward), c.up)) > 1e-4f)) {
                throw Error(where + "camera up is parallel to the viewing direction");
            }
        }
    }
    return a;
}

Light parseLight(const JsonNode& node) {
    node.expectKeys({"type", "name", "position", "direction", "target", "color", "intensity",
                     "inner_cone_deg", "outer_cone_deg", "range"});
    Light light;
    const std::string type = node["type"].string();
    if (type == "point")
        light.type = LightType::Point;
    else if (type == "spot")
        light.type = LightType::Spot;
    else if (type == "directional")
        light.type = LightType::Directional;
    else
        node["type"].fail("unknown light type \"" + type + "\" (point, spot, directional)");
    light.name = node.has("name") ? node["name"].string() : node.path();

    std::optional<glm::vec3> position;
    if (node.has("position")) position = node["position"].vec3();
    if (light.type != LightType::Directional && !position) {
        node.fail("missing required key \"position\"");
    }
    if (position) light.position = *position;
    if (light.type == LightType::Point) {
        for (const char* key : {"direction", "target", "inner_cone_deg", "outer_cone_deg"}) {
            if (node.has(key)) node[key].fail("not used by a point light");
        }
    } else {
        light.direction = readDirection(node, position);
    }

    // Radiometric: intensity x color = W/sr (point, spot) or W/m^2 (directional)
    const glm::vec3 color = node.has("color") ? node["color"].color() : glm::vec3(1.0f);
    const double intensity = node["intensity"].numberIn(0.0, 1e12);
    light.color = color;
    light.strength = float(intensity);
    light.intensity = light.color * light.strength;
    if (node.has("range")) light.range = float(node["range"].numberIn(0.0, 1e12));

    if (light.type == LightType::Spot) {
        double outer = 45.0, inner = 0.0;
        if (node.has("outer_cone_deg")) {
            const JsonNode key = node["outer_cone_deg"];
            outer = key.number();
            if (!(outer > 0.0 && outer <= 90.0)) {
                key.fail("out of range: must be in (0, 90] degrees (got " + key.raw().dump() + ")");
            }
        }
        if (node.has("inner_cone_deg")) inner = node["inner_cone_deg"].numberIn(0.0, 90.0);
        if (outer < inner) node.fail("outer_cone_deg must be >= inner_cone_deg");
        light.innerConeRad = glm::radians(float(inner));
        light.outerConeRad = glm::radians(float(outer));
    } else {
        for (const char* key : {"inner_cone_deg", "outer_cone_deg"}) {
            if (node.has(key)) node[key].fail("only spot lights have cone angles");
        }
    }
    return light;
}

SceneDescription parseSceneDescription(const JsonNode& root, const std::string& baseDir) {
    root.expectKeys({"name", "gltf", "procedural", "camera", "resolution", "exposure_ev", "lights",
                     "extra_lights", "material_overrides", "remove_emissive", "scale", "translate",
                     "animation"});
    SceneDescription d;
    d.context = root.context();
    if (root.has("name")) {
        d.name = root["name"].string();
        if (d.name->empty()) root["name"].fail("must not be empty");
    }

    // Geometry source: exactly one of "gltf" and "procedural"
    if (root.has("gltf") == root.has("procedural")) {
        root.fail("give exactly one of \"gltf\" and \"procedural\"");
    }
    if (root.has("gltf")) {
        const std::filesystem::path rel = root["gltf"].string();
        d.gltfPath = (rel.is_absolute() ? rel : std::filesystem::path(baseDir) / rel)
                         .lexically_normal()
                         .string();
    } else {
        const JsonNode proc = root["procedural"];
        const std::string generator = proc["generator"].string();
        if (generator == "cornell_box") {
            d.cornellBox = cornellBoxParamsFromJson(proc);
        } else if (generator == "two_rooms") {
            d.twoRooms = twoRoomsParamsFromJson(proc);
        } else {
            proc["generator"].fail("unknown generator \"" + generator +
                                   "\" (cornell_box, two_rooms)");
        }
    }

    if (root.has("camera")) d.camera = parseCamera(root["camera"]);
    if (root.has("resolution")) {
        const JsonNode r = root["resolution"];
        if (r.arraySize() != 2) r.fail("expected [width, height]");
        d.resolution = glm::ivec2(r.item(0).integerIn(1, 16384), r.item(1).integerIn(1, 16384));
    }
    if (root.has("exposure_ev")) d.exposureEv = float(root["exposure_ev"].numberIn(-64, 64));
    if (root.has("lights")) d.lights = parseLights(root["lights"]);
    if (root.has("extra_lights")) d.extraLights = parseLights(root["extra_lights"]);
    if (root.has("material_overrides")) {
        const JsonNode overrides = root["material_overrides"];
        if (!overrides.raw().is_object()) overrides.fail("expected an object of material names");
        for (const auto& item : overrides.raw().items()) {
            d.materialOverrides.push_back(
                parseMaterialOverride(overrides[item.key().c_str()], item.key()));
        }
    }
    d.removeEmissive = booleanOr(root, "remove_emissive", false);
    if (root.has("scale")) {
        d.scale = root["scale"].numberIn(1e-6, 1e6);
        if (root.has("animation") && d.scale != 1.0)
            root["scale"].fail(
                "cannot scale an animated scene (its keys are in the unscaled units)");
    }
    if (root.has("translate")) {
        const JsonNode t = root["translate"];
        const glm::vec3 v = t.vec3();
        for (int i = 0; i < 3; ++i)
            if (!(std::abs(double(v[i])) <= 1e7))
                t.fail("out of range: every component must be in [-1e7, 1e7] (got " +
                       std::to_string(v[i]) + ")");
        if (root.has("animation") && v != glm::vec3(0.0f))
            t.fail("cannot translate an animated scene (its keys are in the untranslated frame)");
        d.translate = glm::dvec3(v);
    }
    if (root.has("animation")) d.animation = parseAnimation(root["animation"]);
    return d;
}

}  // namespace gilab
