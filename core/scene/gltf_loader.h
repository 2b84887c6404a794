#pragma once
/** Internal pieces of the glTF loader (the public entry point is loadGltf in scene_loader.h). */
#include <map>
#include <string>
#include <tuple>

#include "core/scene/scene.h"

namespace tinygltf {
class Model;
}

namespace gilab::gltf {

/** Result of reading one glTF file; caps are not computed yet. */
struct LoadResult {
    Scene scene;
    bool hasCamera = false;  // the file placed a perspective camera
};

/** Reads a .gltf/.glb into a world-space scene (no framing camera, no computeCaps()). */
LoadResult loadFile(const std::string& path);

/** Converts materials and the textures they use; `file` names the glTF in messages. */
class MaterialConverter {
public:
    MaterialConverter(const tinygltf::Model& model, const std::string& file, Scene& scene)
        : m_model(model), m_file(file), m_scene(scene) {}

    /** Appends every glTF material to scene.materials (same order, same indices). */
    void convertAll();
    /** Index of a plain default material for primitives without one (added on first use). */
    uint32_t defaultMaterial();

private:
    int texture(int gltfTexture, int texCoord, ColorSpace space, const std::string& material);

    const tinygltf::Model& m_model;
    std::string m_file;
    Scene& m_scene;
    // (image, wrap S, wrap T, colour space) -> index into scene.textures
    std::map<std::tuple<int, int, int, ColorSpace>, int> m_textures;
    int m_defaultMaterial = -1;
};

}  // namespace gilab::gltf
