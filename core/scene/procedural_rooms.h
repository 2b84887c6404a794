#pragma once
/**
 * Two box rooms side by side along x, joined by a door in the wall between them: the stress
 * scene for light that reaches a room only through an opening (scenes/stress/two_rooms_door.json,
 * docs/scenes.md). Room A spans x in [0, sx], the dividing wall x in [sx, sx + t] (a closed
 * slab: two faces and the door's jambs), room B x in [sx + t, 2 sx + t]; both y in [0, sy]
 * (y up) and z in [0, sz]. The door is a rectangle of the wall's face in fractions of z and y.
 *
 * | JSON key       | field         | default                | meaning                          |
 * |----------------|---------------|------------------------|----------------------------------|
 * | room_size      | roomSize      | [0.5, 0.5, 0.5]        | m, interior of each room (x,y,z) |
 * | wall_thickness | wallThickness | 0.02                   | m, the dividing slab, > 0        |
 * | door           | door          | [0.35, 0.0, 0.65, 0.6] | [z0, y0, z1, y1] in [0, 1] of the|
 * |                |               |                        | wall face (z0 < z1, y0 < y1)     |
 * | door_open      | doorOpen      | true                   | false: a solid wall, no door     |
 * | white          | white         | [0.7, 0.7, 0.7]        | albedo of every other surface    |
 * | red            | red           | [0.63, 0.065, 0.05]    | albedo of room A's far wall      |
 *
 * The outer shell is six single quads facing in (floor and ceiling, frontWall at z = 0,
 * backWall at z = sz, farWallA (red) at x = 0, farWallB at x = 2 sx + t), each spanning both
 * rooms; the slab "divider" rests on it. Materials are Lambertian and double-sided. The
 * generator makes no lights (a scene file gives them) and places a camera in room B looking at
 * the door.
 */
#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace gilab {

class JsonNode;

struct TwoRoomsParams {
    glm::vec3 roomSize{0.5f, 0.5f, 0.5f};
    float wallThickness = 0.02f;
    glm::vec4 door{0.35f, 0.0f, 0.65f, 0.6f};  // z0, y0, z1, y1 in [0, 1], z0 < z1, y0 < y1
    bool doorOpen = true;
    glm::vec3 white{0.7f, 0.7f, 0.7f};
    glm::vec3 red{0.63f, 0.065f, 0.05f};
};

/** Where things are, in metres (for tests and measurements). */
struct TwoRoomsLayout {
    Bounds roomA;  // interior of room A (x in [0, sx])
    Bounds roomB;  // interior of room B (x in [sx + t, 2 sx + t])
    Bounds door;   // the opening through the slab (x in [sx, sx + t]); meaningful when open
};

TwoRoomsLayout twoRoomsLayout(const TwoRoomsParams& params);

/** Builds the two rooms (caps computed, name "two_rooms"); bad parameters throw gilab::Error. */
Scene makeTwoRooms(const TwoRoomsParams& params);

/** Reads the parameters from a `"procedural"` JSON object (the keys in the table above). */
TwoRoomsParams twoRoomsParamsFromJson(const JsonNode& node);

}  // namespace gilab
