#include "core/scene/procedural_cornell.h"

#include <cmath>
#include <string>

#include "core/scene/mesh_builder.h"
#include "core/util/error.h"
#include "core/util/json_reader.h"

namespace gilab {

namespace {

constexpr float kMm = 0.001f;  // the measured data is in millimetres

// Measured block tops (mm), in order around the top; the sides drop to the floor.
constexpr glm::vec3 kShortBlock[4] = {{130.0f, 165.0f, 65.0f},
                                      {82.0f, 165.0f, 225.0f},
                                      {240.0f, 165.0f, 272.0f},
                                      {290.0f, 165.0f, 114.0f}};
constexpr glm::vec3 kTallBlock[4] = {{423.0f, 330.0f, 247.0f},
                                     {265.0f, 330.0f, 296.0f},
                                     {314.0f, 330.0f, 456.0f},
                                     {472.0f, 330.0f, 406.0f}};
// Light opening in the ceiling (mm): x in [213, 343], z in [227, 332].
constexpr glm::vec2 kLightLo{213.0f, 227.0f};
constexpr glm::vec2 kLightHi{343.0f, 332.0f};

[[noreturn]] void invalid(const std::string& message) {
    throw Error("cornell_box: " + message);
}

/** A block: the measured top quad plus four sides down to the floor, facing outwards. */
void addBlock(Scene& scene, const glm::vec3 (&topMm)[4], uint32_t material) {
    glm::vec3 top[4], bottom[4], centre(0.0f);
    for (int i = 0; i < 4; ++i) {
        top[i] = topMm[i] * kMm;
        bottom[i] = glm::vec3(top[i].x, 0.0f, top[i].z);
        centre += 0.25f * top[i];
    }
    appendQuad(scene, top[0], top[1], top[2], top[3], glm::vec3(0.0f, 1.0f, 0.0f), material);
    for (int i = 0; i < 4; ++i) {
        const int k = (i + 1) % 4;
        glm::vec3 facing = 0.5f * (top[i] + top[k]) - centre;
        facing.y = 0.0f;
        appendQuad(scene, bottom[i], bottom[k], top[k], top[i], facing, material);
    }
}

void validate(const CornellBoxParams& p) {
    auto finiteNonNegative = [](const glm::vec3& c) {
        return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.x >= 0.0f &&
               c.y >= 0.0f && c.z >= 0.0f;
    };
    if (!(p.wallThickness >= 0.0f && p.wallThickness <= 1.0f)) {
        invalid("wall_thickness must be in [0, 1] m");
    }
    if (!(p.albedoScale >= 0.0f) || !std::isfinite(p.albedoScale)) {
        invalid("albedo_scale must be >= 0 (got " + std::to_string(p.albedoScale) + ")");
    }
    if (!finiteNonNegative(p.white) || !finiteNonNegative(p.red) || !finiteNonNegative(p.green) ||
        (p.floor && !finiteNonNegative(*p.floor))) {
        invalid("white, red, green and floor must be finite and >= 0");
    }
    if (!finiteNonNegative(p.lightRadiance)) invalid("light_radiance must be finite and >= 0");
    const glm::vec2 half = 0.5f * (kLightHi - kLightLo) * kMm * p.lightSize;
    const glm::vec2 centre = 0.5f * (kLightHi + kLightLo) * kMm;
    if (!(p.lightSize > 0.0f) || centre.x + half.x > kCornellRoomSize.x ||
        centre.y + half.y > kCornellRoomSize.z || centre.x - half.x < 0.0f ||
        centre.y - half.y < 0.0f) {
        invalid("light_size must be > 0 and keep the light inside the ceiling");
    }
    if (!(p.lightOffset >= 0.0f && p.lightOffset < 0.1f)) {
        invalid("light_offset must be in [0, 0.1) m");
    }
    if (p.opening) {
        const glm::vec4 o = *p.opening;
        if (!(o.x >= 0.0f && o.x < o.z && o.z <= 1.0f && o.y >= 0.0f && o.y < o.w && o.w <= 1.0f)) {
            invalid("opening must be [u0, v0, u1, v1] with 0 <= u0 < u1 <= 1, 0 <= v0 < v1 <= 1");
        }
    }
}

}  // namespace

Scene makeCornellBox(const CornellBoxParams& p) {
    validate(p);
    Scene scene;
    scene.name = "cornell_box";
    scene.sourcePath = "<procedural cornell_box>";

    auto albedo = [&](const glm::vec3& c) { return glm::clamp(c * p.albedoScale, 0.0f, 1.0f); };
    const glm::vec3 size = kCornellRoomSize;
    const float t = p.wallThickness;
    const float zFront = p.frontWall ? -t : 0.0f;  // outer extent of the slabs towards -z
    const float depth = size.z + t - zFront;
    const glm::vec3 X(1.0f, 0.0f, 0.0f), Y(0.0f, 1.0f, 0.0f), Z(0.0f, 0.0f, 1.0f);
    const std::optional<glm::vec4> noHole;

    // Walls: floor and ceiling span the full outer footprint, the sides cover the corners.
    appendWall(scene, {-t, 0.0f, zFront}, (size.x + 2 * t) * X, depth * Z, Y, t, noHole,
               appendLambertianMaterial(scene, "floor", albedo(p.floor.value_or(p.white))));
    appendWall(scene, {-t, size.y, zFront}, (size.x + 2 * t) * X, depth * Z, -Y, t, noHole,
               appendLambertianMaterial(scene, "ceiling", albedo(p.white)));
    appendWall(scene, {0.0f, 0.0f, size.z}, size.x * X, size.y * Y, -Z, t, p.opening,
               appendLambertianMaterial(scene, "backWall", albedo(p.white)));
    appendWall(scene, {0.0f, 0.0f, zFront}, depth * Z, size.y * Y, X, t, noHole,
               appendLambertianMaterial(scene, "rightWall", albedo(p.green)));
    appendWall(scene, {size.x, 0.0f, zFront}, depth * Z, size.y * Y, -X, t, noHole,
               appendLambertianMaterial(scene, "leftWall", albedo(p.red)));
    if (p.frontWall) {
        appendWall(scene, {0.0f, 0.0f, 0.0f}, size.x * X, size.y * Y, Z, t, noHole,
                   appendLambertianMaterial(scene, "frontWall", albedo(p.white)));
    }
    if (p.blocks) {
        addBlock(scene, kShortBlock, appendLambertianMaterial(scene, "shortBox", albedo(p.white)));
        addBlock(scene, kTallBlock, appendLambertianMaterial(scene, "tallBox", albedo(p.white)));
    }

    // The light: a one-sided emitter facing down, just below the ceiling
    if (p.light) {
        const uint32_t m = appendLambertianMaterial(scene, "light", glm::vec3(0.78f));
        scene.materials[m].emissiveFactor = p.lightRadiance;
        scene.materials[m].doubleSided = false;
        const glm::vec2 centre = 0.5f * (kLightHi + kLightLo) * kMm;
        const glm::vec2 half = 0.5f * (kLightHi - kLightLo) * kMm * p.lightSize;
        const float y = size.y - p.lightOffset;
        appendQuad(scene, {centre.x - half.x, y, centre.y - half.y},
                   {centre.x + half.x, y, centre.y - half.y},
                   {centre.x + half.x, y, centre.y + half.y},
                   {centre.x - half.x, y, centre.y + half.y}, -Y, m);
    }

    // Camera: the measured one, or just inside the front wall when the box is closed
    scene.camera.position = {0.278f, 0.273f, p.frontWall ? 0.02f : -0.8f};
    scene.camera.target = scene.camera.position + Z;
    scene.camera.up = Y;
    scene.camera.vfovRad = glm::radians(39.3f);
    scene.camera.nearZ = 0.01f;
    scene.camera.farZ = 100.0f;
    scene.computeCaps();
    return scene;
}

CornellBoxParams cornellBoxParamsFromJson(const JsonNode& node) {
    node.expectKeys({"generator", "wall_thickness", "albedo_scale", "white", "red", "green",
                     "floor", "light_size", "light_radiance", "light_offset", "light", "blocks",
                     "front_wall", "opening"});
    CornellBoxParams p;
    if (node.has("wall_thickness")) p.wallThickness = float(node["wall_thickness"].numberIn(0, 1));
    if (node.has("albedo_scale")) p.albedoScale = float(node["albedo_scale"].numberIn(0, 1e3));
    if (node.has("white")) p.white = node["white"].color(1.0);
    if (node.has("red")) p.red = node["red"].color(1.0);
    if (node.has("green")) p.green = node["green"].color(1.0);
    if (node.has("floor")) p.floor = node["floor"].color(1.0);
    if (node.has("light_size")) p.lightSize = float(node["light_size"].numberIn(1e-3, 4.0));
    if (node.has("light_radiance")) p.lightRadiance = node["light_radiance"].color();
    if (node.has("light_offset")) p.lightOffset = float(node["light_offset"].numberIn(0, 0.099));
    p.light = booleanOr(node, "light", p.light);
    p.blocks = booleanOr(node, "blocks", p.blocks);
    p.frontWall = booleanOr(node, "front_wall", p.frontWall);
    if (node.has("opening")) {
        const JsonNode o = node["opening"];
        if (o.arraySize() != 4) o.fail("expected [u0, v0, u1, v1]");
        glm::vec4 r;
        for (int i = 0; i < 4; ++i)
            r[i] = float(o.item(size_t(i)).numberIn(0.0, 1.0));
        if (!(r.x < r.z && r.y < r.w)) o.fail("need u0 < u1 and v0 < v1");
        p.opening = r;
    }
    return p;
}

}  // namespace gilab
