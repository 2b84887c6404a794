#include "core/scene/procedural_rooms.h"

#include <cmath>
#include <optional>
#include <string>

#include "core/scene/mesh_builder.h"
#include "core/util/error.h"
#include "core/util/json_reader.h"

namespace gilab {

namespace {

[[noreturn]] void invalid(const std::string& message) {
    throw Error("two_rooms: " + message);
}

void validate(const TwoRoomsParams& p) {
    auto finitePositive = [](const glm::vec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && v.x > 0.0f &&
               v.y > 0.0f && v.z > 0.0f;
    };
    auto albedo = [](const glm::vec3& c) {
        return glm::all(glm::greaterThanEqual(c, glm::vec3(0.0f))) &&
               glm::all(glm::lessThanEqual(c, glm::vec3(1.0f)));  // false for NaN
    };
    if (!finitePositive(p.roomSize)) invalid("room_size must be finite and > 0 in x, y and z");
    if (!(p.wallThickness > 0.0f && p.wallThickness <= 1.0f)) {
        invalid("wall_thickness must be in (0, 1] m (got " + std::to_string(p.wallThickness) + ")");
    }
    const glm::vec4 d = p.door;
    if (!(d.x >= 0.0f && d.x < d.z && d.z <= 1.0f && d.y >= 0.0f && d.y < d.w && d.w <= 1.0f)) {
        invalid("door must be [z0, y0, z1, y1] with 0 <= z0 < z1 <= 1, 0 <= y0 < y1 <= 1");
    }
    if (!albedo(p.white) || !albedo(p.red)) invalid("white and red must be in [0, 1]");
}

}  // namespace

TwoRoomsLayout twoRoomsLayout(const TwoRoomsParams& p) {
    const glm::vec3 s = p.roomSize;
    const float t = p.wallThickness;
    TwoRoomsLayout layout;
    layout.roomA = {glm::vec3(0.0f), s};
    layout.roomB = {glm::vec3(s.x + t, 0.0f, 0.0f), glm::vec3(2.0f * s.x + t, s.y, s.z)};
    layout.door = {glm::vec3(s.x, p.door.y * s.y, p.door.x * s.z),
                   glm::vec3(s.x + t, p.door.w * s.y, p.door.z * s.z)};
    return layout;
}

Scene makeTwoRooms(const TwoRoomsParams& p) {
    validate(p);
    Scene scene;
    scene.name = "two_rooms";
    scene.sourcePath = "<procedural two_rooms>";

    const glm::vec3 s = p.roomSize;
    const float t = p.wallThickness;
    const float length = 2.0f * s.x + t;  // both rooms and the slab along x
    const glm::vec3 X(1.0f, 0.0f, 0.0f), Y(0.0f, 1.0f, 0.0f), Z(0.0f, 0.0f, 1.0f);
    const std::optional<glm::vec4> noHole;

    // The shell: one quad per side, facing in, spanning both rooms (the slab rests on it)
    appendWall(scene, glm::vec3(0.0f), length * X, s.z * Z, Y, 0.0f, noHole,
               appendLambertianMaterial(scene, "floor", p.white));
    appendWall(scene, {0.0f, s.y, 0.0f}, length * X, s.z * Z, -Y, 0.0f, noHole,
               appendLambertianMaterial(scene, "ceiling", p.white));
    appendWall(scene, glm::vec3(0.0f), length * X, s.y * Y, Z, 0.0f, noHole,
               appendLambertianMaterial(scene, "frontWall", p.white));
    appendWall(scene, {0.0f, 0.0f, s.z}, length * X, s.y * Y, -Z, 0.0f, noHole,
               appendLambertianMaterial(scene, "backWall", p.white));
    appendWall(scene, glm::vec3(0.0f), s.z * Z, s.y * Y, X, 0.0f, noHole,
               appendLambertianMaterial(scene, "farWallA", p.red));
    appendWall(scene, {length, 0.0f, 0.0f}, s.z * Z, s.y * Y, -X, 0.0f, noHole,
               appendLambertianMaterial(scene, "farWallB", p.white));

    // The dividing slab: room A's face at x = sx extruded to x = sx + t, the door cut through
    // with its jambs (u = z, v = y, so the door's [z0, y0, z1, y1] is the hole as given)
    const std::optional<glm::vec4> door = p.doorOpen ? std::optional<glm::vec4>(p.door) : noHole;
    appendWall(scene, {s.x, 0.0f, 0.0f}, s.z * Z, s.y * Y, -X, t, door,
               appendLambertianMaterial(scene, "divider", p.white));

    // Camera: in room B near its far wall, looking at the door's centre on room B's side
    const TwoRoomsLayout layout = twoRoomsLayout(p);
    scene.camera.position = {length - 0.1f * s.x, 0.6f * s.y, 0.85f * s.z};
    scene.camera.target = {s.x + t, layout.door.center().y, layout.door.center().z};
    scene.camera.up = Y;
    scene.camera.vfovRad = glm::radians(60.0f);
    scene.camera.nearZ = 0.001f;
    scene.camera.farZ = 100.0f;
    scene.computeCaps();
    return scene;
}

TwoRoomsParams twoRoomsParamsFromJson(const JsonNode& node) {
    node.expectKeys(
        {"generator", "room_size", "wall_thickness", "door", "door_open", "white", "red"});
    TwoRoomsParams p;
    if (node.has("room_size")) {
        const JsonNode r = node["room_size"];
        if (r.arraySize() != 3) r.fail("expected [x, y, z]");
        for (int i = 0; i < 3; ++i)
            p.roomSize[i] = float(r.item(size_t(i)).numberIn(1e-3, 100.0));
    }
    if (node.has("wall_thickness")) {
        p.wallThickness = float(node["wall_thickness"].numberIn(1e-4, 1.0));
    }
    if (node.has("door")) {
        const JsonNode d = node["door"];
        if (d.arraySize() != 4) d.fail("expected [z0, y0, z1, y1]");
        for (int i = 0; i < 4; ++i)
            p.door[i] = float(d.item(size_t(i)).numberIn(0.0, 1.0));
        if (!(p.door.x < p.door.z && p.door.y < p.door.w)) d.fail("need z0 < z1 and y0 < y1");
    }
    p.doorOpen = booleanOr(node, "door_open", p.doorOpen);
    if (node.has("white")) p.white = node["white"].color(1.0);
    if (node.has("red")) p.red = node["red"].color(1.0);
    return p;
}

}  // namespace gilab
