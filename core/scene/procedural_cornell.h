#pragma once
/**
 * The classic Cornell box, built from the measured data of the Cornell University Program of
 * Computer Graphics (converted from millimetres to metres): room 0.556 x 0.5488 x 0.5592 m with
 * the corner at the origin (x to the red wall, y up, z to the back wall), the short and tall
 * blocks at their measured corners, the 0.13 x 0.105 m ceiling light and the camera at
 * (0.278, 0.273, -0.8) looking +z with a 39.3 degree vertical field of view.
 *
 * | JSON key         | field          | default              | meaning                          |
 * |------------------|----------------|----------------------|----------------------------------|
 * | wall_thickness   | wallThickness  | 0                    | m; 0 = one quad per wall, > 0 =  |
 * |                  |                |                      | closed slabs (light-leak tests)  |
 * | albedo_scale     | albedoScale    | 1                    | scales every wall/block albedo   |
 * |                  |                |                      | (result clamped to [0, 1])       |
 * | white/red/green  | white/red/green| measured colours     | albedo overrides (linear RGB)    |
 * | floor            | floor          | = white              | floor albedo override            |
 * | light_size       | lightSize      | 1                    | light quad scale about its centre|
 * | light_radiance   | lightRadiance  | [17, 12, 4]          | W/(m^2 sr)                       |
 * | light_offset     | lightOffset    | 0.0005               | m the light hangs below ceiling  |
 * | light            | light          | true                 | include the emissive quad        |
 * | blocks           | blocks         | true                 | include the two blocks           |
 * | front_wall       | frontWall      | false                | close the box (camera moves in)  |
 * | opening          | opening        | none                 | [u0,v0,u1,v1] window in the back |
 * |                  |                |                      | wall; u = x / 0.556, v = y/0.5488|
 *
 * Walls face into the box, blocks face out, the light faces down. Material names follow the
 * shared glTF version: floor, ceiling, backWall, leftWall (red), rightWall (green), frontWall,
 * shortBox, tallBox, light. All are Lambertian (metallic 0, roughness 1).
 */
#include <optional>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab {

class JsonNode;

struct CornellBoxParams {
    float wallThickness = 0.0f;
    float albedoScale = 1.0f;
    glm::vec3 white{0.725f, 0.71f, 0.68f};
    glm::vec3 red{0.63f, 0.065f, 0.05f};
    glm::vec3 green{0.14f, 0.45f, 0.091f};
    std::optional<glm::vec3> floor;  // the floor's albedo; white when unset
    float lightSize = 1.0f;
    glm::vec3 lightRadiance{17.0f, 12.0f, 4.0f};
    float lightOffset = 0.0005f;
    bool light = true;
    bool blocks = true;
    bool frontWall = false;
    std::optional<glm::vec4> opening;  // u0, v0, u1, v1 in [0, 1], u0 < u1, v0 < v1
};

/** Room size in metres (x, y, z): the interior the walls enclose. */
inline constexpr glm::vec3 kCornellRoomSize{0.556f, 0.5488f, 0.5592f};

/** Builds the box (caps computed, name "cornell_box"); invalid parameters throw gilab::Error. */
Scene makeCornellBox(const CornellBoxParams& params);

/** Reads the parameters from a `"procedural"` JSON object (the keys in the table above). */
CornellBoxParams cornellBoxParamsFromJson(const JsonNode& node);

}  // namespace gilab
