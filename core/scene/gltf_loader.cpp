// glTF 2.0 -> Scene: file reading, extensions, the node hierarchy, meshes, cameras, lights.
#include "core/scene/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include <tiny_gltf.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/scene/gltf_accessor.h"
#include "core/scene/mesh_builder.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"

namespace gilab {

namespace gltf {

namespace {

namespace fs = std::filesystem;

const std::set<std::string> kSupportedExtensions = {"KHR_lights_punctual",
                                                    "KHR_materials_emissive_strength"};

/** tinygltf's multi-line messages as one line. */
std::string oneLine(const std::string& text) {
    std::istringstream in(text);
    std::string line, out;
    while (std::getline(in, line)) {
        if (!line.empty()) out += (out.empty() ? "" : "; ") + line;
    }
    return out;
}

/** The first external file (buffer or image uri) the reader below refused, and why. */
struct RefusedFile {
    std::string path;
    std::string problem;
};

/**
 * tinygltf's file reader for every file a glTF references, reading regular files only: a uri
 * naming a folder made tinygltf's reader fail with std::bad_alloc, and a FIFO or device would
 * never end. The first refusal is kept in `user` (a RefusedFile) for the error message.
 */
bool readRegularFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* user) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    std::string problem;
    if (fs::is_directory(status))
        problem = "is a folder, not a file";
    else if (!fs::exists(status))
        problem = "does not exist";
    else if (!fs::is_regular_file(status))
        problem = "is not a regular file";
    if (problem.empty()) return tinygltf::ReadWholeFile(out, err, path, nullptr);
    auto* refused = static_cast<RefusedFile*>(user);
    if (refused->path.empty()) *refused = {path, problem};
    if (err) *err += problem;
    return false;
}

/** tinygltf's FileExists by stat: its own opens the file, which blocks on a FIFO. */
bool fileExists(const std::string& path, void*) {
    std::error_code ec;
    return fs::exists(path, ec);
}

/** The uri of `file` as written in a glTF in `dir` (tinygltf joins the two), for messages. */
std::string uriOf(const fs::path& file, const fs::path& dir) {
    if (dir.empty()) return file.string();
    const fs::path rel = file.lexically_relative(dir);
    return rel.empty() || *rel.begin() == ".." ? file.string() : rel.string();
}

bool hasGlbMagic(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    return in.gcount() == 4 && std::string(magic, 4) == "glTF";
}

/** Shortest round-trip text of a number, for messages. */
std::string num(double v) {
    std::ostringstream out;
    out.precision(9);
    out << v;
    return out.str();
}

std::string count(size_t n, const char* what) {
    return std::to_string(n) + " " + what;
}

/** "node 3 'name'" (the name when it has one). */
std::string nodeLabel(const tinygltf::Model& model, size_t index) {
    const std::string& name = model.nodes[index].name;
    return "node " + std::to_string(index) + (name.empty() ? "" : " '" + name + "'");
}

bool isFinite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) {
            if (!std::isfinite(m[c][r])) return false;
        }
    }
    return true;
}

/** The node's local matrix; malformed or non-finite TRS/matrix values are an error. */
glm::mat4 localTransform(const tinygltf::Node& node, const std::string& what) {
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16) {
            throw Error(what + ": matrix has " + std::to_string(node.matrix.size()) +
                        " numbers (16 required)");
        }
        glm::mat4 m;
        for (int i = 0; i < 16; ++i)
            m[i / 4][i % 4] = float(node.matrix[size_t(i)]);
        if (!isFinite(m)) throw Error(what + ": matrix has a NaN or infinite entry");
        const float eps = 1e-6f;
        if (std::abs(m[0][3]) > eps || std::abs(m[1][3]) > eps || std::abs(m[2][3]) > eps ||
            std::abs(m[3][3] - 1.0f) > eps) {
            throw Error(what + ": matrix is not an affine TRS matrix (its last row must be " +
                        "0 0 0 1)");
        }
        return m;
    }
    auto checkVector = [&](const std::vector<double>& v, size_t size, const char* name) {
        if (!v.empty() && v.size() != size) {
            throw Error(what + ": " + name + " has " + std::to_string(v.size()) + " numbers (" +
                        std::to_string(size) + " required)");
        }
        for (double x : v) {
            if (!std::isfinite(float(x))) {
                throw Error(what + ": " + name + " has a NaN or infinite (or float-overflowing)" +
                            " value");
            }
        }
    };
    checkVector(node.translation, 3, "translation");
    checkVector(node.rotation, 4, "rotation");
    checkVector(node.scale, 3, "scale");
    glm::mat4 m(1.0f);
    if (node.translation.size() == 3) {
        m[3] = glm::vec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (node.rotation.size() == 4) {
        const glm::dquat dq(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        const double length = glm::length(dq);
        if (!(length > 0.0) || !std::isfinite(length)) {
            throw Error(what + ": rotation quaternion [" + num(node.rotation[0]) + ", " +
                        num(node.rotation[1]) + ", " + num(node.rotation[2]) + ", " +
                        num(node.rotation[3]) + "] has zero length");
        }
        m = m * glm::mat4_cast(glm::quat(dq / length));
    }
    if (node.scale.size() == 3) {
        m = m * glm::scale(glm::mat4(1.0f), glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
    }
    if (!isFinite(m)) throw Error(what + ": transform is not finite");
    return m;
}

/**
 * The unit world direction of local `dir` under `world`, or nullopt where the transform
 * collapses or overflows it (zero scale, a singular or non-finite matrix).
 */
std::optional<glm::dvec3> worldDirection(const glm::mat4& world, const glm::vec3& dir) {
    const glm::dvec3 d = glm::dmat3(glm::mat3(world)) * glm::dvec3(dir);
    const double length = glm::length(d);
    if (!(length > 0.0) || !std::isfinite(length)) return std::nullopt;
    const glm::dvec3 unit = d / length;
    if (!std::isfinite(unit.x) || !std::isfinite(unit.y) || !std::isfinite(unit.z)) {
        return std::nullopt;
    }
    // The float direction must still be unit length (no float underflow)
    if (std::abs(glm::length(glm::vec3(unit)) - 1.0f) > 1e-3f) return std::nullopt;
    return unit;
}

std::vector<glm::vec3> toVec3(const std::vector<float>& f) {
    std::vector<glm::vec3> out(f.size() / 3);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
    return out;
}

std::vector<glm::vec2> toVec2(const std::vector<float>& f) {
    std::vector<glm::vec2> out(f.size() / 2);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = {f[2 * i], f[2 * i + 1]};
    return out;
}

/** Deepest node nesting walked (recursively) before the file is refused. */
constexpr size_t kMaxNodeDepth = 1024;

/** Checks every camera's projection (glTF 2.0, 5.12-5.14) before any node uses it. */
void checkCameras(const tinygltf::Model& model, const std::string& file) {
    for (size_t i = 0; i < model.cameras.size(); ++i) {
        const tinygltf::Camera& cam = model.cameras[i];
        const std::string what = file + ": camera " + std::to_string(i) +
                                 (cam.name.empty() ? "" : " '" + cam.name + "'");
        if (cam.type == "orthographic") continue;  // ignored with a warning where used
        if (cam.type != "perspective") {
            throw Error(what + ": unknown type '" + cam.type + "' (perspective or orthographic)");
        }
        const tinygltf::PerspectiveCamera& p = cam.perspective;
        const float yfov = float(p.yfov), znear = float(p.znear), zfar = float(p.zfar);
        if (!(std::isfinite(yfov) && yfov > 0.0f && yfov < glm::pi<float>())) {
            throw Error(what + ": invalid yfov " + num(p.yfov) + " (must be in (0, pi) radians)");
        }
        if (!(std::isfinite(znear) && znear > 0.0f)) {
            throw Error(what + ": invalid znear " + num(p.znear) + " (must be > 0)");
        }
        // tinygltf reads an absent zfar (infinite projection) as 0
        if (p.zfar != 0.0 && !(std::isfinite(zfar) && zfar > znear)) {
            throw Error(what + ": invalid zfar " + num(p.zfar) + " (must be greater than znear " +
                        num(p.znear) + ")");
        }
        if (p.aspectRatio != 0.0 && !(std::isfinite(p.aspectRatio) && p.aspectRatio > 0.0)) {
            throw Error(what + ": invalid aspectRatio " + num(p.aspectRatio) + " (must be > 0)");
        }
    }
}

/** Checks every KHR_lights_punctual light's colour, intensity, range and cone angles. */
void checkLights(const tinygltf::Model& model, const std::string& file) {
    for (size_t i = 0; i < model.lights.size(); ++i) {
        const tinygltf::Light& src = model.lights[i];
        const std::string what =
            file + ": light " + std::to_string(i) + (src.name.empty() ? "" : " '" + src.name + "'");
        if (src.type != "point" && src.type != "spot" && src.type != "directional") {
            throw Error(what + ": unknown type '" + src.type + "' (point, spot or directional)");
        }
        if (!src.color.empty() && src.color.size() != 3) {
            throw Error(what + ": color has " + std::to_string(src.color.size()) +
                        " numbers (3 required)");
        }
        for (double c : src.color) {
            if (!(std::isfinite(float(c)) && c >= 0.0)) {
                throw Error(what + ": invalid color component " + num(c) +
                            " (must be finite and >= 0)");
            }
        }
        if (!(std::isfinite(float(src.intensity)) && src.intensity >= 0.0)) {
            throw Error(what + ": invalid intensity " + num(src.intensity) +
                        " (must be finite and >= 0)");
        }
        // tinygltf reads an absent range (infinite) as 0
        if (src.range != 0.0 && !(std::isfinite(float(src.range)) && src.range > 0.0)) {
            throw Error(what + ": invalid range " + num(src.range) + " (must be > 0)");
        }
        const double inner = src.spot.innerConeAngle, outer = src.spot.outerConeAngle;
        if (src.type == "spot" && !(inner >= 0.0 && inner <= outer && outer > 0.0 &&
                                    outer <= glm::half_pi<double>() + 1e-6)) {
            throw Error(what + ": invalid cone angles inner " + num(inner) + ", outer " +
                        num(outer) + " (need 0 <= inner <= outer <= pi/2, outer > 0)");
        }
    }
}

/** Depth-first walk over the node hierarchy, flattening meshes, cameras and lights. */
class NodeWalker {
public:
    NodeWalker(const tinygltf::Model& model, const std::string& file, Scene& scene,
               MaterialConverter& materials)
        : m_model(model),
          m_file(file),
          m_scene(scene),
          m_materials(materials),
          m_onStack(model.nodes.size(), false) {}

    /** `index` was range-checked by rootNodes() (roots and children alike). */
    void walk(int index, const glm::mat4& parent) {
        if (index < 0 || size_t(index) >= m_model.nodes.size()) {
            throw Error(m_file + ": node " + std::to_string(index) + " does not exist");
        }
        if (m_onStack[size_t(index)]) {
            throw Error(m_file + ": node hierarchy has a cycle at node " + std::to_string(index));
        }
        if (m_depth >= kMaxNodeDepth) {
            throw Error(m_file + ": node hierarchy is deeper than " +
                        std::to_string(kMaxNodeDepth) + " levels at node " + std::to_string(index));
        }
        m_onStack[size_t(index)] = true;
        ++m_depth;
        const tinygltf::Node& node = m_model.nodes[size_t(index)];
        const std::string what = m_file + ": " + nodeLabel(m_model, size_t(index));
        const glm::mat4 world = parent * localTransform(node, what);
        if (!isFinite(world)) {
            throw Error(what + ": world transform is not finite (float overflow)");
        }
        if (node.mesh != -1) addMesh(node, what, world);
        if (node.camera != -1) addCamera(node, what, world);
        if (auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end()) {
            addLight(node, what, ext->second, world);
        }
        for (int child : node.children)
            walk(child, world);
        m_onStack[size_t(index)] = false;
        --m_depth;
    }

    MeshStats stats;
    bool hasCamera = false;

private:
    void addMesh(const tinygltf::Node& node, const std::string& nodeWhat, const glm::mat4& world) {
        if (node.mesh < 0 || size_t(node.mesh) >= m_model.meshes.size()) {
            throw Error(nodeWhat + " references mesh " + std::to_string(node.mesh) +
                        ", which does not exist (the file has " +
                        count(m_model.meshes.size(), "meshes") + ")");
        }
        if (node.skin >= 0) {
            m_scene.warnings.push_back(m_file + ": skin of node '" + node.name +
                                       "' ignored (bind pose used)");
        }
        const tinygltf::Mesh& mesh = m_model.meshes[size_t(node.mesh)];
        const std::string meshName = mesh.name.empty() ? std::to_string(node.mesh) : mesh.name;
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const std::string what =
                m_file + ": mesh '" + meshName + "' primitive " + std::to_string(p);
            if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) {
                m_scene.warnings.push_back(what + ": mode " + std::to_string(prim.mode) +
                                           " is not triangles; skipped");
                continue;
            }
            if (!prim.targets.empty()) {
                m_scene.warnings.push_back(what + ": morph targets ignored");
            }
            auto attr = [&](const char* name) -> std::optional<int> {
                auto it = prim.attributes.find(name);
                if (it == prim.attributes.end()) return std::nullopt;
                return it->second;
            };
            const auto position = attr("POSITION");
            if (!position) throw Error(what + ": no POSITION attribute");
            PrimitiveData data;
            data.positions =
                toVec3(readFloats(m_model, *position, 3, what, "POSITION", ComponentRule::Float));
            if (const auto normal = attr("NORMAL")) {
                data.normals =
                    toVec3(readFloats(m_model, *normal, 3, what, "NORMAL", ComponentRule::Float));
            }
            if (const auto uv = attr("TEXCOORD_0")) {
                data.uvs = toVec2(readFloats(m_model, *uv, 2, what, "TEXCOORD_0",
                                             ComponentRule::FloatOrNormalizedUnsigned));
            }
            if (prim.indices != -1) data.indices = readIndices(m_model, prim.indices, what);
            uint32_t material = 0;
            if (prim.material == -1) {
                material = m_materials.defaultMaterial();
            } else if (prim.material >= 0 && size_t(prim.material) < m_model.materials.size()) {
                material = uint32_t(prim.material);  // scene.materials[i] is glTF material i
            } else {
                throw Error(what + ": material " + std::to_string(prim.material) +
                            " does not exist (the file has " +
                            count(m_model.materials.size(), "materials") + ")");
            }
            appendPrimitive(m_scene, data, world, material, what, stats);
        }
    }

    void addCamera(const tinygltf::Node& node, const std::string& nodeWhat,
                   const glm::mat4& world) {
        if (node.camera < 0 || size_t(node.camera) >= m_model.cameras.size()) {
            throw Error(nodeWhat + " references camera " + std::to_string(node.camera) +
                        ", which does not exist (the file has " +
                        count(m_model.cameras.size(), "cameras") + ")");
        }
        const tinygltf::Camera& cam = m_model.cameras[size_t(node.camera)];
        if (cam.type != "perspective") {
            m_scene.warnings.push_back(m_file + ": " + cam.type + " camera '" + cam.name +
                                       "' ignored (perspective only)");
            return;
        }
        // Every perspective camera node is checked, including those after the first
        const std::string what = nodeWhat + " (camera " + std::to_string(node.camera) +
                                 (cam.name.empty() ? "" : " '" + cam.name + "'") + ")";
        const std::string degenerate =
            what + ": degenerate world transform (zero scale, singular or non-finite matrix)";
        // glTF cameras look down local -Z with +Y up.
        const auto forward = worldDirection(world, glm::vec3(0.0f, 0.0f, -1.0f));
        const auto up = worldDirection(world, glm::vec3(0.0f, 1.0f, 0.0f));
        if (!forward || !up || glm::length(glm::cross(*forward, *up)) < 1e-6) {
            throw Error(degenerate + "; the camera has no view direction");
        }
        Camera c = m_scene.camera;
        c.position = glm::vec3(world * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        c.target = c.position + glm::vec3(*forward);
        c.up = glm::vec3(*up);
        const glm::vec3 f = c.forward(), r = c.right();
        if (!std::isfinite(f.x + f.y + f.z + r.x + r.y + r.z) ||
            std::abs(glm::length(f) - 1.0f) > 1e-3f || std::abs(glm::length(r) - 1.0f) > 1e-3f) {
            throw Error(what + ": position is too far from the origin for a float view direction");
        }
        if (hasCamera) return;  // the first camera wins
        c.vfovRad = float(cam.perspective.yfov);
        c.nearZ = float(cam.perspective.znear);  // > 0 (checkCameras)
        c.farZ = cam.perspective.zfar != 0.0 ? float(cam.perspective.zfar)
                                             : std::max(1000.0f, 10 * c.nearZ);
        m_scene.camera = c;
        hasCamera = true;
    }

    void addLight(const tinygltf::Node& node, const std::string& nodeWhat,
                  const tinygltf::Value& ext, const glm::mat4& world) {
        if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber()) {
            throw Error(nodeWhat + ": KHR_lights_punctual has no light index");
        }
        const int index = ext.Get("light").GetNumberAsInt();
        if (index < 0 || size_t(index) >= m_model.lights.size()) {
            throw Error(nodeWhat + " references light " + std::to_string(index) +
                        ", which does not exist (the file has " +
                        count(m_model.lights.size(), "lights") + ")");
        }
        const tinygltf::Light& src = m_model.lights[size_t(index)];  // checked by checkLights
        Light light;
        light.name = src.name.empty() ? node.name : src.name;
        const std::string what = nodeWhat + " (light " + std::to_string(index) +
                                 (src.name.empty() ? "" : " '" + src.name + "'") + ")";
        if (src.type == "point")
            light.type = LightType::Point;
        else if (src.type == "spot")
            light.type = LightType::Spot;
        else
            light.type = LightType::Directional;

        // Radiometric as-is: intensity x color is W/sr (point, spot) or W/m^2 (directional).
        light.color = src.color.size() == 3 ? glm::vec3(src.color[0], src.color[1], src.color[2])
                                            : glm::vec3(1.0f);
        light.strength = float(src.intensity);
        light.intensity = light.color * light.strength;
        if (!std::isfinite(light.intensity.x + light.intensity.y + light.intensity.z)) {
            throw Error(what + ": intensity x color overflows a float");
        }
        light.range = float(src.range);
        light.innerConeRad = float(src.spot.innerConeAngle);
        light.outerConeRad = float(src.spot.outerConeAngle);
        const auto direction = worldDirection(world, glm::vec3(0.0f, 0.0f, -1.0f));
        if (!direction) {
            throw Error(what + ": degenerate world transform (zero scale, singular or " +
                        "non-finite matrix); the light has no direction");
        }
        light.position = glm::vec3(world * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        light.direction = glm::vec3(*direction);
        m_scene.lights.push_back(light);
    }

    const tinygltf::Model& m_model;
    const std::string& m_file;
    Scene& m_scene;
    MaterialConverter& m_materials;
    std::vector<bool> m_onStack;
    size_t m_depth = 0;
};

void checkExtensions(const tinygltf::Model& model, const std::string& file, Scene& scene) {
    for (const std::string& ext : model.extensionsRequired) {
        if (!kSupportedExtensions.count(ext)) {
            throw Error(file + ": requires unsupported glTF extension " + ext);
        }
    }
    for (const std::string& ext : model.extensionsUsed) {
        if (!kSupportedExtensions.count(ext)) {
            scene.warnings.push_back(file + ": glTF extension " + ext + " is not supported; " +
                                     "ignored");
        }
    }
}

/**
 * Checks every node and scene reference (children in range, at most one parent per node,
 * scene roots in range, unique and parentless, the default scene in range) and returns the
 * root nodes to walk: the default scene's (else scene 0's; without scenes, every parentless
 * node).
 */
std::vector<int> rootNodes(const tinygltf::Model& model, const std::string& file) {
    const size_t n = model.nodes.size();
    std::vector<int> parent(n, -1);
    for (size_t i = 0; i < n; ++i) {
        for (int c : model.nodes[i].children) {
            if (c < 0 || size_t(c) >= n) {
                throw Error(file + ": " + nodeLabel(model, i) + " lists child node " +
                            std::to_string(c) + ", which does not exist (the file has " +
                            count(n, "nodes") + ")");
            }
            if (parent[size_t(c)] == int(i)) {
                throw Error(file + ": " + nodeLabel(model, i) + " lists child node " +
                            std::to_string(c) + " twice");
            }
            if (parent[size_t(c)] != -1) {
                throw Error(file + ": " + nodeLabel(model, size_t(c)) + " has two parents (nodes " +
                            std::to_string(parent[size_t(c)]) + " and " + std::to_string(i) +
                            "); a node may have at most one");
            }
            parent[size_t(c)] = int(i);
        }
    }
    if (model.defaultScene < -1 ||
        (model.defaultScene >= 0 && size_t(model.defaultScene) >= model.scenes.size())) {
        throw Error(file + ": default scene " + std::to_string(model.defaultScene) +
                    " does not exist (the file has " + count(model.scenes.size(), "scenes") + ")");
    }
    if (model.scenes.empty()) {
        std::vector<int> roots;
        for (size_t i = 0; i < n; ++i) {
            if (parent[i] == -1) roots.push_back(int(i));
        }
        return roots;
    }
    const size_t s = model.defaultScene >= 0 ? size_t(model.defaultScene) : 0;
    const std::string what = file + ": scene " + std::to_string(s);
    std::vector<bool> listed(n, false);
    for (int r : model.scenes[s].nodes) {
        if (r < 0 || size_t(r) >= n) {
            throw Error(what + " lists node " + std::to_string(r) +
                        ", which does not exist (the file has " + count(n, "nodes") + ")");
        }
        if (parent[size_t(r)] != -1) {
            throw Error(what + " lists " + nodeLabel(model, size_t(r)) +
                        " as a root, but it is a child of node " +
                        std::to_string(parent[size_t(r)]));
        }
        if (listed[size_t(r)]) {
            throw Error(what + " lists " + nodeLabel(model, size_t(r)) + " twice");
        }
        listed[size_t(r)] = true;
    }
    return model.scenes[s].nodes;
}

}  // namespace

LoadResult loadFile(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(path + ": glTF file not found");

    // Parse with tinygltf (buffers and images are read and decoded here)
    tinygltf::TinyGLTF loader;
    RefusedFile refused;
    tinygltf::FsCallbacks callbacks{};
    callbacks.FileExists = &fileExists;
    callbacks.ExpandFilePath = &tinygltf::ExpandFilePath;
    callbacks.ReadWholeFile = &readRegularFile;
    callbacks.WriteWholeFile = &tinygltf::WriteWholeFile;
    callbacks.user_data = &refused;
    loader.SetFsCallbacks(callbacks);
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = hasGlbMagic(path) ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                                      : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    // A refused buffer fails the load, a refused image only warns: both are errors here
    if (!refused.path.empty()) {
        const std::string uri = uriOf(refused.path, fs::path(path).parent_path());
        throw Error(path + ": the uri \"" + uri + "\"" +
                    (uri == refused.path ? "" : " (" + refused.path + ")") + " " + refused.problem +
                    "; a buffer's or image's uri must name a file");
    }
    if (!ok) throw Error(path + ": malformed glTF: " + oneLine(err.empty() ? warn : err));

    LoadResult result;
    Scene& scene = result.scene;
    scene.name = fs::path(path).stem().string();
    scene.sourcePath = path;
    scene.loadedFiles.push_back(path);
    const fs::path dir = fs::path(path).parent_path();
    auto isFile = [](const std::string& uri) { return !uri.empty() && uri.rfind("data:", 0) != 0; };
    for (const auto& buffer : model.buffers) {
        if (isFile(buffer.uri)) {
            scene.loadedFiles.push_back((dir / buffer.uri).lexically_normal().string());
        }
    }
    for (const auto& image : model.images) {  // tinygltf reads every image, used or not
        if (isFile(image.uri) && !image.image.empty()) {
            scene.loadedFiles.push_back((dir / image.uri).lexically_normal().string());
        }
    }
    checkExtensions(model, path, scene);
    if (!warn.empty()) scene.warnings.push_back(path + ": " + oneLine(warn));

    // Materials first (primitives index them), then the node hierarchy
    checkCameras(model, path);
    checkLights(model, path);
    const std::vector<int> roots = rootNodes(model, path);
    MaterialConverter materials(model, path, scene);
    materials.convertAll();
    NodeWalker walker(model, path, scene, materials);
    for (int root : roots)
        walker.walk(root, glm::mat4(1.0f));
    result.hasCamera = walker.hasCamera;

    if (walker.stats.degenerateTriangles > 0) {
        scene.warnings.push_back(path + ": dropped " +
                                 std::to_string(walker.stats.degenerateTriangles) +
                                 " degenerate triangles (repeated index or zero area)");
    }
    if (walker.stats.recomputedNormals > 0) {
        scene.warnings.push_back(path + ": recomputed " +
                                 std::to_string(walker.stats.recomputedNormals) +
                                 " zero-length normals from the faces");
    }
    if (scene.triangleCount() == 0) throw Error(path + ": contains no triangles");
    return result;
}

}  // namespace gltf

Scene loadGltf(const std::string& path) {
    gltf::LoadResult result = gltf::loadFile(path);
    Scene& scene = result.scene;
    scene.computeCaps();
    if (!result.hasCamera) {
        scene.camera = makeFramingCamera(scene.caps.bounds);
        scene.warnings.push_back(path + ": no camera in the file; framing the bounds");
    }
    return std::move(result.scene);
}

}  // namespace gilab
