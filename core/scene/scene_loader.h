#pragma once
/**
 * Scene loading: JSON scene descriptions (docs/scenes.md), glTF 2.0 files and the built-in
 * default scene. Every loader flattens to world space, fills `Scene::warnings` and
 * `Scene::loadedFiles`, calls `Scene::computeCaps()` last, and throws gilab::Error with a
 * message naming the file and the problem.
 */
#include <string>

#include "core/scene/scene.h"

namespace gilab {

/**
 * Loads a scene description (.json). `path` may carry the variant as `file.json#variant`;
 * giving it both ways with different names is an error. Relative paths inside the file are
 * relative to the file's folder. `Scene::name` = file stem (or the "name" key) + "#variant".
 */
Scene loadSceneFile(const std::string& path, const std::string& variant = "");

/**
 * Loads a glTF 2.0 file (.gltf or .glb): geometry, materials, textures, the first camera and
 * KHR_lights_punctual lights. Without a camera in the file, a camera framing the bounds is
 * made and a warning added.
 */
Scene loadGltf(const std::string& path);

/**
 * Any scene a command line or config names: "" or "builtin" (the built-in Cornell box), a
 * scene description "file.json[#variant]", or a glTF file "file.gltf" / "file.glb" (camera from
 * the file, else a framing camera and a warning). Anything else throws gilab::Error saying
 * what was expected.
 */
Scene loadScene(const std::string& spec);

/** The scene used when none is given: the procedural Cornell box with its ceiling area light. */
Scene makeBuiltinDefaultScene();

/** A camera looking at the centre of `bounds` along -z from far enough to see all of it. */
Camera makeFramingCamera(const Bounds& bounds);

}  // namespace gilab
