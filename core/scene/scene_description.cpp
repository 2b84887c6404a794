#include "core/scene/scene_description.h"

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

}  // namespace

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
    light.intensity = color * float(intensity);
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
                     "extra_lights", "material_overrides", "remove_emissive"});
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
        if (generator != "cornell_box") {
            proc["generator"].fail("unknown generator \"" + generator + "\" (cornell_box)");
        }
        d.cornellBox = cornellBoxParamsFromJson(proc);
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
    return d;
}

}  // namespace gilab
