// glTF 2.0 -> Scene: file reading, extensions, the node hierarchy, meshes, cameras, lights.
#include "core/scene/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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

bool hasGlbMagic(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    in.read(magic, 4);
    return in.gcount() == 4 && std::string(magic, 4) == "glTF";
}

glm::mat4 localTransform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) {
        glm::mat4 m;
        for (int i = 0; i < 16; ++i)
            m[i / 4][i % 4] = float(node.matrix[size_t(i)]);
        return m;
    }
    glm::mat4 m(1.0f);
    if (node.translation.size() == 3) {
        m[3] = glm::vec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (node.rotation.size() == 4) {
        glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                    float(node.rotation[2]));
        if (glm::length(q) > 0.0f) m = m * glm::mat4_cast(glm::normalize(q));
    }
    if (node.scale.size() == 3) {
        m = m * glm::scale(glm::mat4(1.0f), glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
    }
    return m;
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

    void walk(int index, const glm::mat4& parent) {
        if (index < 0 || size_t(index) >= m_model.nodes.size()) {
            throw Error(m_file + ": node " + std::to_string(index) + " does not exist");
        }
        if (m_onStack[size_t(index)]) {
            throw Error(m_file + ": node hierarchy has a cycle at node " + std::to_string(index));
        }
        m_onStack[size_t(index)] = true;
        const tinygltf::Node& node = m_model.nodes[size_t(index)];
        const glm::mat4 world = parent * localTransform(node);
        if (node.mesh >= 0) addMesh(node, world);
        if (node.camera >= 0) addCamera(node, world);
        if (auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end()) {
            addLight(node, ext->second, world);
        }
        for (int child : node.children)
            walk(child, world);
        m_onStack[size_t(index)] = false;
    }

    MeshStats stats;
    bool hasCamera = false;

private:
    void addMesh(const tinygltf::Node& node, const glm::mat4& world) {
        if (size_t(node.mesh) >= m_model.meshes.size()) {
            throw Error(m_file + ": node '" + node.name + "' references missing mesh " +
                        std::to_string(node.mesh));
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
            auto attr = [&](const char* name) {
                auto it = prim.attributes.find(name);
                return it == prim.attributes.end() ? -1 : it->second;
            };
            if (attr("POSITION") < 0) throw Error(what + ": no POSITION attribute");
            PrimitiveData data;
            data.positions = toVec3(readFloats(m_model, attr("POSITION"), 3, what + " POSITION"));
            if (attr("NORMAL") >= 0) {
                data.normals = toVec3(readFloats(m_model, attr("NORMAL"), 3, what + " NORMAL"));
            }
            if (attr("TEXCOORD_0") >= 0) {
                data.uvs = toVec2(readFloats(m_model, attr("TEXCOORD_0"), 2, what + " UV"));
            }
            if (prim.indices >= 0) data.indices = readIndices(m_model, prim.indices, what);
            uint32_t material = 0;
            if (prim.material >= 0 && size_t(prim.material) < m_scene.materials.size()) {
                material = uint32_t(prim.material);
            } else if (prim.material >= 0) {
                throw Error(what + ": material " + std::to_string(prim.material) +
                            " does not exist");
            } else {
                material = m_materials.defaultMaterial();
            }
            appendPrimitive(m_scene, data, world, material, what, stats);
        }
    }

    void addCamera(const tinygltf::Node& node, const glm::mat4& world) {
        if (hasCamera) return;  // the first camera wins
        const tinygltf::Camera& cam = m_model.cameras.at(size_t(node.camera));
        if (cam.type != "perspective") {
            m_scene.warnings.push_back(m_file + ": " + cam.type + " camera '" + cam.name +
                                       "' ignored (perspective only)");
            return;
        }
        if (!(cam.perspective.yfov > 0.0 && cam.perspective.yfov < glm::pi<double>())) {
            throw Error(m_file + ": camera '" + cam.name + "' has invalid yfov");
        }
        // glTF cameras look down local -Z with +Y up.
        Camera& c = m_scene.camera;
        c.position = glm::vec3(world * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        const glm::vec3 forward = glm::normalize(glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f));
        c.target = c.position + forward;
        c.up = glm::normalize(glm::mat3(world) * glm::vec3(0.0f, 1.0f, 0.0f));
        c.vfovRad = float(cam.perspective.yfov);
        if (cam.perspective.znear > 0.0) c.nearZ = float(cam.perspective.znear);
        c.farZ = cam.perspective.zfar > cam.perspective.znear ? float(cam.perspective.zfar)
                                                              : std::max(1000.0f, 10 * c.nearZ);
        hasCamera = true;
    }

    void addLight(const tinygltf::Node& node, const tinygltf::Value& ext, const glm::mat4& world) {
        const int index = ext.Has("light") ? ext.Get("light").GetNumberAsInt() : -1;
        if (index < 0 || size_t(index) >= m_model.lights.size()) {
            throw Error(m_file + ": node '" + node.name + "' references missing light " +
                        std::to_string(index));
        }
        const tinygltf::Light& src = m_model.lights[size_t(index)];
        Light light;
        light.name = src.name.empty() ? node.name : src.name;
        const std::string what = m_file + ": light '" + light.name + "'";
        if (src.type == "point")
            light.type = LightType::Point;
        else if (src.type == "spot")
            light.type = LightType::Spot;
        else if (src.type == "directional")
            light.type = LightType::Directional;
        else
            throw Error(what + " has unknown type '" + src.type + "'");

        // Radiometric as-is: intensity x color is W/sr (point, spot) or W/m^2 (directional).
        const glm::vec3 color = src.color.size() == 3
                                    ? glm::vec3(src.color[0], src.color[1], src.color[2])
                                    : glm::vec3(1.0f);
        light.color = color;
        light.strength = float(src.intensity);
        light.intensity = light.color * light.strength;
        if (!std::isfinite(src.intensity) || src.intensity < 0.0 ||
            glm::any(glm::lessThan(color, glm::vec3(0.0f)))) {
            throw Error(what + " has a negative or non-finite intensity/color");
        }
        light.range = float(src.range);
        light.innerConeRad = float(src.spot.innerConeAngle);
        light.outerConeRad = float(src.spot.outerConeAngle);
        if (light.type == LightType::Spot &&
            !(light.innerConeRad >= 0.0f && light.innerConeRad <= light.outerConeRad &&
              light.outerConeRad > 0.0f && light.outerConeRad <= glm::half_pi<float>() + 1e-6f)) {
            throw Error(what + " has invalid cone angles (need 0 <= inner <= outer <= pi/2)");
        }
        light.position = glm::vec3(world * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        light.direction = glm::normalize(glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f));
        m_scene.lights.push_back(light);
    }

    const tinygltf::Model& m_model;
    const std::string& m_file;
    Scene& m_scene;
    MaterialConverter& m_materials;
    std::vector<bool> m_onStack;
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

std::vector<int> rootNodes(const tinygltf::Model& model) {
    if (!model.scenes.empty()) {
        const int s = model.defaultScene >= 0 ? model.defaultScene : 0;
        return model.scenes.at(size_t(s)).nodes;
    }
    // No scenes: every node that is nobody's child.
    std::vector<bool> isChild(model.nodes.size(), false);
    for (const auto& node : model.nodes) {
        for (int c : node.children) {
            if (c >= 0 && size_t(c) < isChild.size()) isChild[size_t(c)] = true;
        }
    }
    std::vector<int> roots;
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        if (!isChild[i]) roots.push_back(int(i));
    }
    return roots;
}

}  // namespace

LoadResult loadFile(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(path + ": glTF file not found");

    // Parse with tinygltf (buffers and images are read and decoded here)
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool ok = hasGlbMagic(path) ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                                      : loader.LoadASCIIFromFile(&model, &err, &warn, path);
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
    MaterialConverter materials(model, path, scene);
    materials.convertAll();
    NodeWalker walker(model, path, scene, materials);
    for (int root : rootNodes(model))
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
